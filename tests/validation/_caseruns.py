"""Cached CLI runs of a validation case file, shared by the test modules that score one."""
from click.testing import CliRunner

from sphdvi.cli import main


def cached_runs(tmp_path_factory, score, report, threads=2):
    """A function run(dp, case) -> score(OUT) of ``sphdvi run CASE -o OUT --dp DP``, each
    (dp, case) run once; it prints report(dp, case, errors) and asserts the run completed."""
    cache = {}

    def run(dp, case):
        key = (dp, str(case))
        if key not in cache:
            out = tmp_path_factory.mktemp("case")
            r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--dp", repr(dp), "--threads",
                                          str(threads), "-q"])
            assert r.exit_code == 0, r.output
            e = score(str(out))
            print(report(dp, case, e))
            assert e["status"] == "completed"
            cache[key] = e
        return cache[key]
    return run
