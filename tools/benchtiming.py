"""The timing loop the part-cost benchmarks share (bench_dem, bench_flexstruc, bench_moorings,
bench_relaxzones): methods of the solver's run timed by wrapping them, the best of several rounds of SPH
steps. Not a test."""
import time


def time_part(solver, owner, name: str, t0: float, steps: int, rounds: int) -> tuple:
    """Advance ``solver`` to ``t0``, then time ``rounds`` rounds of ``steps`` steps with the calls of
    ``owner.<name>`` (replaced by a timing wrapper) counted apart; returns the best round's (wall time,
    time in the part, the last dt), in seconds."""
    return time_parts(solver, [(owner, name)], t0, steps, rounds)


def time_parts(solver, parts, t0: float, steps: int, rounds: int) -> tuple:
    """:func:`time_part` with the calls of several methods, ``parts`` a list of (owner, name), counted
    together as the part."""
    spent = [0.0]

    def timing(part):
        def timed(*args, **kwargs):
            t = time.perf_counter()
            try:
                return part(*args, **kwargs)
            finally:
                spent[0] += time.perf_counter() - t
        return timed
    for owner, name in parts:
        setattr(owner, name, timing(getattr(owner, name)))
    solver.run(t0)
    best = None
    for _ in range(rounds):
        spent[0] = 0.0
        t = time.perf_counter()
        for _ in range(steps):
            solver.step()
        wall = time.perf_counter() - t
        if best is None or wall < best[0]:
            best = (wall, spent[0], solver.last_dt)
    return best
