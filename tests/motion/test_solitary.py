"""``<piston_solitary>``: Goring's (1978) generation of solitary waves (Rayleigh, Boussinesq, KdV),
its closed form against the kinematic condition it is built on, and the case format."""
import math

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.motion import SolitaryPaddle, solitary_wave

from run.test_run import REPO, assert_gencase_error

G = 9.81


def paddle(theory=2, heights=(0.02,), durationcoefs=(1.0,), startcoefs=(1.0,), depth=0.1, start=0.0):
    waves = [{"waveheight": h, "durationcoef": d, "startcoef": s}
             for h, d, s in zip(heights, durationcoefs, startcoefs)]
    return SolitaryPaddle({"type": "piston_solitary", "mkbound": 10, "depth": depth, "theory": theory,
                           "start": start, "solitary": waves}, G)


@pytest.mark.parametrize("theory", [1, 2, 3])
def test_the_piston_moves_with_the_waves_depth_averaged_velocity(theory):
    """dX/dt = c η(X, t)/(h + η(X, t)) at every instant (the generation's premise), X(t) the
    integral of that velocity, the stroke Goring's 2H/(κh) (tanh 3.8 of it), and the motion's
    duration 2(3.8 + H/h)/(κc), after which the piston stays."""
    p = paddle(theory, heights=(0.03,))
    w = p.strokes[0]
    kappa, c = solitary_wave(theory, 0.03, 0.1, G)
    assert (w.kappa, w.c) == (kappa, c)
    assert w.duration == pytest.approx(2 * (3.8 + 0.3) / (kappa * c), rel=1e-14)
    assert w.stroke == pytest.approx(2 * 0.03 / (kappa * 0.1) * math.tanh(3.8), rel=1e-6)
    ts = np.linspace(0.0, w.duration, 2001)
    xv = np.array([p._series(t) for t in ts])
    for (t, (x, v)) in zip(ts[1:-1:50], xv[1:-1:50]):
        eta = p.elevation(x, t)[0]
        assert v == pytest.approx(c * eta / (0.1 + eta), rel=1e-10, abs=1e-14)
    # the position is the integral of the velocity (trapezoids, error ~ dt²)
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (xv[1:, 1] + xv[:-1, 1]) * np.diff(ts))])
    assert np.max(np.abs(integral - xv[:, 0])) < 1e-5 * w.stroke
    assert p._series(w.duration + 1.0) == (pytest.approx(w.stroke, rel=1e-12), 0.0)
    assert p._series(-1.0) == (0.0, 0.0)


def test_theories_and_the_crest():
    """Rayleigh's κ is Boussinesq's times √(h/(h + H)); KdV moves at √(gh)(1 + H/2h); the theory's
    crest is H high and leaves the piston when the piston moves fastest."""
    kr, cr = solitary_wave(1, 0.02, 0.1, G)
    kb, cb = solitary_wave(2, 0.02, 0.1, G)
    kk, ck = solitary_wave(3, 0.02, 0.1, G)
    assert kr == pytest.approx(kb * math.sqrt(0.1 / 0.12)) and cr == cb == pytest.approx(math.sqrt(G * 0.12))
    assert kk == kb and ck == pytest.approx(math.sqrt(G * 0.1) * 1.1)
    p = paddle(2)
    w = p.strokes[0]
    xc, tc = w.crest()
    assert p.elevation(xc, tc)[0] == pytest.approx(0.02, rel=1e-12)
    assert p.elevation(xc + 1.0, tc + 1.0 / w.c)[0] == pytest.approx(0.02, rel=1e-12)
    ts = np.linspace(0, w.duration, 4001)
    v = [p._series(t)[1] for t in ts]
    assert ts[int(np.argmax(v))] == pytest.approx(tc, abs=w.duration / 2000)
    with pytest.raises(ValueError):
        solitary_wave(4, 0.02, 0.1)


def test_several_waves_start_a_fraction_of_the_previous_duration_apart_and_add_up():
    p = paddle(2, heights=(0.02, 0.03), durationcoefs=(1.0, 1.2), startcoefs=(1.0, 0.8), start=0.5)
    w1, w2 = p.strokes
    assert w2.start == pytest.approx(0.8 * w1.duration)
    assert w2.duration == pytest.approx(1.2 * 2 * (3.8 + 0.3) / (w2.kappa * w2.c))
    for tau in (0.3, w2.start + 0.1, w1.duration + 0.05, w2.start + w2.duration + 1):
        x, v = p._series(tau)
        assert x == pytest.approx(w1.position(tau)[0] + w2.position(tau)[0])
        assert v == pytest.approx(w1.position(tau)[1] + w2.position(tau)[1])
    assert p.transform(0.4).d[0] == 0.0           # before <start>
    assert p.transform(0.5 + 10).d[0] == pytest.approx(w1.stroke + w2.stroke)


SOLITARY = REPO / "cases" / "waveflume2d" / "CaseWaveSolitary2D_Def.xml"


def with_paddle(tmp_path, body):
    text = SOLITARY.read_text()
    start = text.index("<piston_solitary>", text.index("<wavepaddles>"))
    end = text.index("</piston_solitary>") + len("</piston_solitary>")
    path = tmp_path / "CaseSol_Def.xml"
    path.write_text(text[:start] + f"<piston_solitary>{body}</piston_solitary>" + text[end:])
    return path


def test_the_case_format_and_its_defaults(tmp_path):
    from sphdvi.case.gencase import build_case
    case = with_paddle(tmp_path, '<mkbound value="10"/><depth value="0.1"/><waveheight value="0.02"/>'
                                 '<waves value="3"/><startcoef2 value="0.8"/><waveheight2 value="0.03"/>'
                                 '<durationcoef3 value="1.5"/>')
    spec = build_case(str(case)).case.special["wavepaddles"][0]
    assert spec["theory"] == 2 and spec["start"] == 0.0 and spec["pistondir"] == [1.0, 0.0, 0.0]
    assert spec["solitary"] == [{"waveheight": 0.02, "durationcoef": 1.0, "startcoef": 1.0},
                                {"waveheight": 0.03, "durationcoef": 1.0, "startcoef": 0.8},
                                {"waveheight": 0.03, "durationcoef": 1.5, "startcoef": 0.8}]


@pytest.mark.parametrize("body, message", [
    ('<theory value="4"/>', "theory 4"),
    ('<startcoef2 value="0.5"/>',
     "unknown element <startcoef2> in <piston_solitary> (the case has <waves value=\"1\">)"),
    ('<waves value="2"/><waveheight2 value="0.09"/>', "breaks (H/h > 0.78)"),
    ('<durationcoef value="0"/>', "duration coefficient 0"),
    ('<pistondir x="0" y="0" z="0"/>', "<pistondir> is the zero vector"),
])
def test_bad_solitary_paddles_are_case_errors(tmp_path, body, message):
    case = with_paddle(tmp_path, '<mkbound value="10"/><depth value="0.1"/><waveheight value="0.02"/>' + body)
    assert_gencase_error(case, tmp_path / "g", message)


def test_a_run_moves_the_piston_particles_as_the_theory(tmp_path):
    """The solitary case at dp 0.02: at every output the piston's particles stand where the
    paddle's displacement puts them (the rest of the flume is the validation W6, slow)."""
    from sphdvi.io.vtkhdf import read_step, step_times
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["run", str(SOLITARY), "-o", str(out), "--dp", "0.02", "--tmax", "0.8",
                                  "--tout", "0.2", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    p = paddle(2)
    path = str(out / "particles.vtkhdf")
    first = read_step(path, 0)
    piston = first["Mk"] == 10 + 9 + 1
    order = np.argsort(first["Idp"][piston])
    x0 = first["points"][piston][order, 0]
    times = step_times(path)
    assert len(times) == 5
    for k, t in enumerate(times):
        s = read_step(path, k)
        sel = s["Mk"] == 20
        x = s["points"][sel][np.argsort(s["Idp"][sel]), 0]
        np.testing.assert_allclose(x - x0, p._series(t)[0], atol=1e-9)
    assert p._series(times[-1])[0] > 0.2 * p.strokes[0].stroke      # the piston has moved
