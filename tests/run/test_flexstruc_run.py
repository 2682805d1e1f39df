"""Flexible structures through ``sphdvi run`` (gencase + the SPH loop): Turek & Hron's CSM3 beam
(`cases/flexstruc2d`) falls as a free body until its bending wave reaches the tip, logs its
configuration, resumes bitwise; the run-time refusals."""
import math
from pathlib import Path

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

CSM3 = Path(__file__).resolve().parents[2] / "cases" / "flexstruc2d" / "CaseTurekHronCSM3_Def.xml"


def run(*args):
    r = CliRunner().invoke(main, ["run", *map(str, args), "--threads", "1", "-q"])
    return r


def tip_uz(outdir, t_index):
    """The mean vertical displacement of the two particles beside point A (0.6, 0.2) at output t_index."""
    with h5py.File(Path(outdir) / "particles.vtkhdf", "r") as f:
        g = f["VTKHDF"]
        off, n = g["Steps/PointOffsets"][...], g["NumberOfPoints"][...]
        P, idp = g["Points"][...], g["PointData/Idp"][...]
        t = g["Steps/Values"][...]
        p0, i0 = P[off[0]:off[0] + n[0]], idp[off[0]:off[0] + n[0]]
        d = np.hypot(p0[:, 0] - 0.6, p0[:, 2] - 0.2)
        tip = i0[d < d.min() + 1e-9]
        pk, ik = P[off[t_index]:off[t_index] + n[t_index]], idp[off[t_index]:off[t_index] + n[t_index]]
        return t[t_index], pk[np.isin(ik, tip), 2].mean() - p0[np.isin(i0, tip), 2].mean(), tip.size


def test_csm3_beam_tip_first_falls_freely(tmp_path):
    """A beam under a load switched on at t = 0 starts to move as a free body far from its clamp: the
    clamp's influence spreads along it as sqrt(t sqrt(EI/(rho A))) (flexural waves), 0.07 m by 0.02 s,
    a factor exp(-L^2/(4 l^2)) ~ 1e-3 at the tip, L = 0.35 m. So the tip falls g t^2/2 there."""
    out = tmp_path / "csm3"
    r = run(CSM3, "-o", out, "--tmax", "0.02", "--tout", "0.01")
    assert r.exit_code == 0, r.output
    for k in (1, 2):
        t, uz, ntip = tip_uz(out, k)
        assert ntip == 2
        assert uz == pytest.approx(-0.5 * 2.0 * t * t, rel=0.01), (t, uz)
    log = (out / "run.log").read_text()
    assert "Flexible Structure 0 (mkbound:1):" in log and "Constitutive model: Plane Strain" in log
    # the structure's sound speed (54.77 m/s) exceeds c0 (50): DtIni = h/c_s, DtMin = CoefDtMin h/c_s, as run
    import json
    meta = json.loads((out / "run.json").read_text())
    h = math.sqrt(2.0) * 0.005
    cs = math.sqrt(1.4e6 * 0.6 / (1000 * 1.4 * 0.2))
    assert meta["parameters"]["DtIni"] == pytest.approx(h / cs, rel=1e-12)
    assert meta["parameters"]["DtMin"] == pytest.approx(0.001 * h / cs, rel=1e-12)
    assert meta["parameters_auto"] == {"DtIni": "h/cs_structure", "DtMin": "CoefDtMin*h/cs_structure"}
    assert f"dt=[1.29e-05, {h / cs:.3g}] s" in log
    assert "Sound speed: 54.7723" in log
    assert "(60 clamp particles, 324 flexible)" in log


def test_a_flexible_structure_run_resumes_bitwise(tmp_path):
    for d, tmax in (("a", 0.04), ("b", 0.02)):
        r = run(CSM3, "-o", tmp_path / d, "--tmax", tmax, "--tout", "0.02")
        assert r.exit_code == 0, r.output
    r = run(tmp_path / "b", "--resume", "--tmax", "0.04")
    assert r.exit_code == 0, r.output

    def state(d):
        with h5py.File(tmp_path / d / "restart.h5", "r") as f:
            o = np.argsort(f["state/idp"][...])
            return f["state/pos"][...][o], f["state/vel"][...][o], f["state/rhop"][...][o]
    for x, y in zip(state("a"), state("b")):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("sets, text", [
    (["Boundary=2", "SlipMode=2", "StepAlgorithm=1"], "Flexible structures with mDBC are not allowed with Verlet."),
    (["Boundary=2", "SlipMode=1"], "original mDBC (SlipMode=1)"),
    (["XPeriodicIncZ=0.1"], "periodic conditions"),
])
def test_run_time_refusals(tmp_path, sets, text):
    args = [CSM3, "-o", tmp_path / "o", "--tmax", "0.01"]
    for s in sets:
        args += ["--set", s]
    r = run(*args)
    assert r.exit_code == 2, r.output
    assert text in r.output


def test_a_structure_one_particle_thick_is_refused(tmp_path):
    text = CSM3.read_text().replace('<size x="#0.4-Dp/2" y="0.02" z="#0.02-Dp" />',
                                    '<size x="#0.4-Dp/2" y="0.02" z="0" />')
    case = tmp_path / "CaseThin_Def.xml"
    case.write_text(text)
    r = run(case, "-o", tmp_path / "o", "--tmax", "0.01")
    assert r.exit_code == 2, r.output
    assert "too few neighbours within 2h" in r.output and "two particles thick" in r.output


def test_the_dam_break_example_with_its_elastic_plate_runs(tmp_path):
    """cases/flexstruc2d/CaseDambreakFlexPlate2D_Def.xml at dp 0.005 for 0.01 s: fluid and structure in
    one run; the plate, clamped in the floor, stands still (under its weight it shortens by
    rho g L^2/(2E) ~ 4e-5 m) until the water comes."""
    case = CSM3.parent / "CaseDambreakFlexPlate2D_Def.xml"
    out = tmp_path / "fsi"
    r = run(case, "-o", out, "--dp", "0.005", "--tmax", "0.01", "--tout", "0.01")
    assert r.exit_code == 0, r.output
    with h5py.File(out / "particles.vtkhdf", "r") as f:
        g = f["VTKHDF"]
        off, n = g["Steps/PointOffsets"][...], g["NumberOfPoints"][...]
        P, idp, mk = g["Points"][...], g["PointData/Idp"][...], g["PointData/Mk"][...]
        a = slice(off[0], off[0] + n[0])
        b = slice(off[-1], off[-1] + n[-1])
        o0, o1 = np.argsort(idp[a]), np.argsort(idp[b])
        plate = mk[a][o0] == 13                            # mkbound 2, fluidcount 10
        u = P[b][o1][plate] - P[a][o0][plate]
    assert plate.sum() == 69 and np.abs(u).max() < 2e-4


def test_a_3d_cantilever_tip_first_falls_freely(tmp_path):
    """cases/flexstruc3d/CaseCantilever3D_Def.xml (St Venant-Kirchhoff, 4 x 4 particles across): as the 2D
    beam, the tip (its end face's 16 particles) falls g t^2/2 until the clamp's influence arrives, and the
    square beam does not move sideways."""
    case = CSM3.parents[1] / "flexstruc3d" / "CaseCantilever3D_Def.xml"
    out = tmp_path / "c3d"
    r = run(case, "-o", out, "--tmax", "0.02", "--tout", "0.01")
    assert r.exit_code == 0, r.output
    with h5py.File(out / "particles.vtkhdf", "r") as f:
        g = f["VTKHDF"]
        off, n, t = g["Steps/PointOffsets"][...], g["NumberOfPoints"][...], g["Steps/Values"][...]
        P, idp, mk = g["Points"][...], g["PointData/Idp"][...], g["PointData/Mk"][...]
        p0, i0, m0 = P[off[0]:off[0] + n[0]], idp[off[0]:off[0] + n[0]], mk[off[0]:off[0] + n[0]]
        beam = m0 == m0.max()
        tip = i0[beam & (p0[:, 0] > p0[beam, 0].max() - 1e-9)]
        assert tip.size == 16
        for k in (1, 2):
            pk, ik = P[off[k]:off[k] + n[k]], idp[off[k]:off[k] + n[k]]
            u = pk[np.isin(ik, tip)].mean(axis=0) - p0[np.isin(i0, tip)].mean(axis=0)
            assert u[2] == pytest.approx(-t[k] ** 2, rel=0.01)          # g/2 = 1 m/s^2
            assert abs(u[1]) < 1e-9
    assert "Constitutive model: St. Venant Kirchhoff" in (out / "run.log").read_text()


def test_a_structure_its_clamp_does_not_reach_is_warned(tmp_path):
    """A clamp mk with no particle within 2h of the body holds nothing (DualSPHysics runs it silently)."""
    text = CSM3.read_text().replace('<point x="0.2" y="0.0" z="0.2" />', '<point x="1.5" y="0.0" z="0.2" />')
    case = tmp_path / "CaseFree_Def.xml"
    case.write_text(text)
    with pytest.warns(UserWarning, match=r"clamp mkbound \[0\] lies within 2h of the flexible structure "
                                         r"mkbound=1 .*nothing holds it"):
        r = run(case, "-o", tmp_path / "o", "--tmax", "0.001")
    assert r.exit_code == 0, r.output
