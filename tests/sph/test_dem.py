"""DualSPHysics's DEM contacts (``RigidAlgorithm`` 2, sphdvi.sph.dem) through gencase and ``sphdvi run``:
a block at rest on the floor sinks by Hertz's overlap under its weight, a body dropped on one
particle rebounds to the height of the contact law's own equation of motion, two bodies colliding
keep their momentum; the pair force against its formulas, a tangential force that never pushes
sliding along (where DualSPHysics's would); and the case checks of the materials."""
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.integrate import solve_ivp

from sphdvi.cli import main

DP = 0.01
BOUNCE = Path(__file__).resolve().parents[2] / "cases" / "dem2d" / "CaseDemBounce2D_Def.xml"
STEEL = dict(E=2.1e11, nu=0.3, e=0.8, mu=0.45)
PVC = dict(E=3.0e9, nu=0.3, e=0.6, mu=0.45)


def case_xml(bodies, gravity=-9.81, materials=None, links='<link mkbound="0" property="steel" />', extra="",
             tmax=0.2, tout=0.01, fluid="", fixed_speed=True):
    """A 2D case: a steel floor (mkbound 0, z = 0, x −0.3..0.6) and ``bodies``: (mkbound, drawing
    commands, property) floating bodies of relativeweight 0.5; no fluid unless ``fluid``; without
    gravity a speedsystem of 2.2 m/s (c0 44 m/s, as with gravity) unless not ``fixed_speed``."""
    mats = materials if materials is not None else (material("steel", 2.1e11, 0.3, 0.8, 0.45)
                                                    + material("pvc", 3.0e9, 0.3, 0.6, 0.45))
    draw = "".join(f'<setmkbound mk="{mk}" />{cmds}' for mk, cmds, _ in bodies)
    speed = ('<speedsystem value="0" auto="true" />' if gravity or not fixed_speed else
             '<speedsystem value="2.2" auto="false" />')
    floats = "".join(f'<floating mkbound="{mk}" relativeweight="0.5" property="{prop}" />' for mk, _, prop in bodies)
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<case><casedef>
  <constantsdef><gravity x="0" y="0" z="{gravity}" /><rhop0 value="1000" /><hswl value="0.5" auto="false" />
    <gamma value="7" />{speed}<coefsound value="20" /><speedsound value="0" auto="true" />
    <coefh value="1.0" /><cflnumber value="0.2" /></constantsdef>
  <mkconfig boundcount="240" fluidcount="9" />
  <geometry><definition dp="{DP}"><pointmin x="-0.4" y="0" z="-0.1" /><pointmax x="0.7" y="0" z="0.5" /></definition>
    <commands><mainlist><setshapemode>actual | dp | bound</setshapemode><setdrawmode mode="full" />
      <setmkbound mk="0" /><drawbox><boxfill>solid</boxfill><point x="-0.3" y="-1" z="0" /><size x="0.9" y="2" z="0" />
      </drawbox>{draw}{fluid}</mainlist></commands></geometry>
  <floatings>{floats}</floatings>
  <properties>{mats}<links>{links}</links></properties>
</casedef>
<execution><parameters>
  <parameter key="StepAlgorithm" value="2" /><parameter key="Kernel" value="2" />
  <parameter key="ViscoTreatment" value="1" />
  <parameter key="Visco" value="0.01" /><parameter key="RigidAlgorithm" value="2" />
  <parameter key="TimeMax" value="{tmax}" /><parameter key="TimeOut" value="{tout}" />{extra}
  <simulationdomain><posmin x="default" y="default" z="default" /><posmax x="default" y="default" z="0.4" />
  </simulationdomain>
</parameters></execution></case>"""


def material(name, young=None, poisson=None, restitution=None, kfric=None):
    """A <property> with its values as child elements, the form DualSPHysics's DEM reads (LoadDemData)."""
    values = (("Young_Modulus", young), ("PoissonRatio", poisson), ("Restitution_Coefficient", restitution),
              ("Kfric", kfric))
    return f'<property name="{name}">' + "".join(f'<{k} value="{v}" />' for k, v in values if v is not None) + \
        "</property>"


def box(x, z, w, h):
    return (f'<drawbox><boxfill>solid</boxfill><point x="{x}" y="-1" z="{z}" /><size x="{w}" y="2" z="{h}" />'
            '</drawbox>')


def run(tmp_path, text, name="CaseDem"):
    path = tmp_path / f"{name}_Def.xml"
    path.write_text(text)
    r = CliRunner().invoke(main, ["run", str(path), "-o", str(tmp_path / "out"), "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    rows = np.genfromtxt(tmp_path / "out" / "bodies.csv", delimiter=",", names=True, dtype=None, encoding=None)
    return r, rows


def kn(a, b):
    """DualSPHysics's Hertz stiffness of a pair of particles of materials a and b (N/m^1.5)."""
    tau = sum((1 - m["nu"] ** 2) / m["E"] for m in (a, b))
    return 4.0 / (3.0 * tau) * math.sqrt(DP / 4)


def damping(e, mstar, k):
    le = math.log(e)
    return -2 * le * math.sqrt(mstar * k) / math.sqrt(math.pi + le * le)


def test_a_block_at_rest_on_the_floor_sinks_by_hertzs_overlap(tmp_path):
    """A pvc block (0.11 x 0.09 m: 12 particles on 12 floor particles, 6 kg) drawn one dp above the
    floor settles δ = (M g / (12 k_n))^(2/3) = 8.0 µm lower (within 0.5 %), the floor carrying its
    weight (the DEM force is part of the body's "fluid" force, as in DualSPHysics's FloatingInfo)."""
    _, rows = run(tmp_path, case_xml([(1, box(0.0, 0.01, 0.11, 0.09), "pvc")]))
    mass = 12 * 10 * 1000 * DP * DP * 0.5
    delta = (mass * 9.81 / (12 * kn(PVC, STEEL))) ** (2 / 3)
    assert delta == pytest.approx(8.0e-6, rel=0.01)
    last = rows[-1]
    assert 0.055 - last["z"] == pytest.approx(delta, rel=5e-3)
    log = (tmp_path / "out" / "run.log").read_text()       # DualSPHysics's Run.out "Coefficients for DEM"
    assert "RigidAlgorithm 2 (DCDEM" in log and "mkbound 0 (mk 10): steel" in log and "mkbound 1 (mk 11): pvc" in log
    assert last["ffz"] == pytest.approx(mass * 9.81, rel=1e-6) and abs(last["vz"]) < 1e-9


def _drop_apex(mass, k, gn, gap, g=9.81):
    """The apex after the first bounce of a body of ``mass`` dropped from ``gap`` above touching on
    one contact: M y'' = −M g + [y < 0] (k (−y)^1.5 − gn (−y)^0.25 y') (the contact law as coded)."""
    def rhs(t, s):
        y, v = s
        f = k * (-y) ** 1.5 - gn * (-y) ** 0.25 * v if y < 0 else 0.0
        return [v, -g + f / mass]

    def apex(t, s):
        return s[1]
    apex.direction = -1.0
    sol = solve_ivp(rhs, (math.sqrt(2 * gap / g) + 1e-3, 1.0), [-1e-12, -math.sqrt(2 * g * gap)], method="LSODA",
                    events=apex, rtol=1e-10, atol=1e-13, max_step=1e-5)
    return sol.y_events[0][0][0]


def test_a_body_dropped_on_one_particle_rebounds_as_the_contact_law_says(tmp_path):
    """cases/dem2d/CaseDemBounce2D: a pvc block (11 x 9 particles) with a one-particle foot under its
    middle, dropped 1 cm onto the floor: one pair in contact (DualSPHysics's m* = M/2 against a wall,
    e = (0.6 + 0.8)/2 = 0.7). Its rebound apex against that of the contact law's own equation of
    motion, integrated here (y < 0: the overlap; 4.38 mm, below e² of the drop: the law's
    restitution is not the input's): the contact is integrated by the SPH step, so the error falls
    with the step (measured −5.9 % at CFL 0.2, −1.6 % at 0.05, −0.4 % at 0.0125: first order)."""
    mass = (11 * 9 + 1) * 1000 * DP * DP * 0.5
    gap = 0.01                  # the foot at z = 0.02 touches the floor row (z = 0) at z = dp
    k = kn(PVC, STEEL)
    expected = _drop_apex(mass, k, damping(0.7, mass / 2, k), gap)
    assert expected == pytest.approx(0.004379, rel=1e-3) and expected < 0.7 ** 2 * gap
    text = BOUNCE.read_text()
    errors = []
    for cfl in (0.2, 0.05):
        out = tmp_path / f"cfl{cfl}"
        out.mkdir()
        _, rows = run(out, text.replace('cflnumber value="0.2"', f'cflnumber value="{cfl}"'))
        after = rows["time"] > math.sqrt(2 * gap / 9.81) + 0.005
        apex = rows["z"][after].max() - (rows["z"][0] - gap)
        errors.append(apex / expected - 1)
    print("apex errors at CFL 0.2, 0.05:", errors)
    assert abs(errors[0]) < 0.08 and abs(errors[1]) < 0.025 and abs(errors[1]) < abs(errors[0]) / 2


def test_two_bodies_colliding_keep_their_momentum(tmp_path):
    """No gravity: two pvc discs' worth of blocks (6 x 6 particles) drawn 2 cm apart, one moving at
    0.5 m/s towards the other at rest. Through and after the collision the total momentum stays
    M v0 within 1e-9 (the pair forces are equal and opposite), and the struck one moves on."""
    bodies = [(1, box(0.0, 0.2, 0.05, 0.05), "pvc"), (2, box(0.08, 0.2, 0.05, 0.05), "pvc")]
    text = case_xml(bodies, gravity=0.0, tmax=0.12, tout=0.005).replace(
        'property="pvc" />', 'property="pvc"><linearvelini x="0.5" y="0" z="0" /></floating>', 1)
    _, rows = run(tmp_path, text)
    b1, b2 = rows[rows["body"] == "floating1"], rows[rows["body"] == "floating2"]
    mass = 36 * 1000 * DP * DP * 0.5
    p = mass * (b1["vx"] + b2["vx"])
    assert p == pytest.approx(mass * 0.5, rel=1e-9)
    assert b2["vx"][-1] > 0.2 and b1["vx"][-1] < b2["vx"][-1]


def _pair(vel, over, mat_i, mat_j, body_i, body_j, wall, dtforce):
    """The DEM kernel on two 2D particles, i (floating, of mass 0.05 kg) ``over`` below touching j (a
    wall or another body) straight under it, i moving at ``vel``: (ace of i, viscdt of i)."""
    from sphdvi.sph.dem import DemTable, dem_serial
    h = DP * math.sqrt(2)
    nb = np.zeros((2, 8))
    nb[0, :4] = [0.0, DP - over, vel[0], vel[1]]
    nb[1, :4] = [0.0, 0.0, 0.0, 0.0]
    nb[:, 6] = 0.05
    ptype = np.array([2, 0 if wall else 2], np.int8)
    table = DemTable([-1, 0, 1], [(1 - m["nu"] ** 2) / m["E"] for m in (mat_i, mat_j)],
                     [mat_i["e"], mat_j["e"]], [mat_i["mu"], mat_j["mu"]], [body_i, body_j])
    ace, viscdt = np.zeros((2, 3)), np.zeros(2)
    idx = np.arange(2)
    dem_serial(True, nb, ptype, np.zeros(2, np.int64), idx, np.array([0, 2]), 1, 1, 1, 1, (2 * h) ** 2,
               np.array([1, 2], np.int32), table.mat_of_mk, table.tau, table.restitution, table.kfric,
               table.body_mass, DP, dtforce, ace, viscdt, 2, np.zeros((1, 3)), np.zeros(30))
    return ace[0], viscdt[0]


@pytest.mark.parametrize("wall", [True, False])
def test_the_pair_force_is_dualsphysicss(wall):
    """One pair, i sliding at 0.2 m/s over j with an overlap of 1e-4 m and approaching at 0.1 m/s:
    the normal force k_n δ^1.5 − g_n δ^0.25 v_n (m* = M_i/2 against a wall, M_i M_j/(M_i + M_j)
    between bodies), the tangential one (k_n Δt − g_n) v_t/3.5 (opposing: k_n Δt < g_n here), each
    over the particle's mass, and the dt term 8/t_c, t_c = 3.21 (m*/k_n)^0.4 |v_n|^−0.2; to round-off."""
    k = kn(PVC, STEEL)
    mstar = 3.0 if wall else 6.0 * 4.0 / 10.0
    gn = damping(0.7, mstar, k)
    over, vn, vt, dtf = 1e-4, -0.1, 0.2, 4e-5
    assert k * dtf < gn
    a, visc = _pair((vt, vn), over, PVC, STEEL, 6.0, 4.0, wall, dtf)
    fn = k * over ** 1.5 - gn * over ** 0.25 * vn
    ft = (k * dtf - gn) * vt / 3.5
    assert a[2] == pytest.approx(fn / 0.05, rel=1e-12) and a[0] == pytest.approx(ft / 0.05, rel=1e-12)
    assert visc == pytest.approx(8.0 / (3.21 * (mstar / k) ** 0.4 * abs(vn) ** -0.2), rel=1e-12)


def test_a_tangential_force_never_drives_sliding():
    """Nearly elastic, light and stiff (e = 0.999, steel on steel, 10 g bodies): k_n Δt > g_n, where
    DualSPHysics's tangential force min(μ f_n tanh 8v, (k_n Δt − g_n) v/3.5) pushes a sliding particle
    along (+x here); sphdvi's is capped at 0: no tangential force, the normal one as before."""
    hard = dict(STEEL, e=0.999)
    k = kn(hard, hard)
    gn = damping(0.999, 0.005, k)
    over, dtf = 1e-5, 4e-5
    assert k * dtf > gn
    a, _ = _pair((0.2, 0.0), over, hard, hard, 0.01, 0.01, True, dtf)
    assert a[0] == 0.0 and a[2] == pytest.approx(k * over ** 1.5 / 0.05, rel=1e-12)
    dualsphysics = min(0.45 * k * over ** 1.5 * math.tanh(1.6), (k * dtf - gn) * 0.2 / 3.5)
    assert dualsphysics > 0.0


def test_gencase_refuses_a_block_without_dem_materials(tmp_path):
    """Every boundary block needs Kfric, Restitution_Coefficient, Young_Modulus and PoissonRatio
    (DualSPHysics stops: "Value of Kfric is invalid."): the floor without a link, and a body whose
    property lacks Young_Modulus, are exit 2 naming the mkbound."""
    path = tmp_path / "CaseBad_Def.xml"
    path.write_text(case_xml([(1, box(0.0, 0.01, 0.11, 0.09), "pvc")], links=""))
    r = CliRunner().invoke(main, ["gencase", str(path), "-o", str(tmp_path / "g")])
    assert r.exit_code == 2 and "mkbound 0 has no property" in r.output and "Traceback" not in r.output
    mats = material("steel", 2.1e11, 0.3, 0.8, 0.45) + material("pvc", None, 0.3, 0.6, 0.45)
    path.write_text(case_xml([(1, box(0.0, 0.01, 0.11, 0.09), "pvc")], materials=mats))
    r = CliRunner().invoke(main, ["gencase", str(path), "-o", str(tmp_path / "g2")])
    assert r.exit_code == 2 and "mkbound 1: its property 'pvc' has no Young_Modulus" in r.output
    assert "<floating>" in r.output


def test_dem_with_fluid_runs_and_leaves_the_fluid_alone(tmp_path):
    """A block resting on the floor under 5 cm of water: it stays on the floor (DEM holds it, FtMode
    Ext: the walls no longer hold floating particles through SPH) and the run completes."""
    fluid = ('<setmkfluid mk="0" /><fillbox x="0.2" y="0" z="0.02"><modefill>void</modefill>'
             '<point x="-0.29" y="-1" z="0.005" /><size x="0.88" y="2" z="0.05" /></fillbox>')
    text = case_xml([(1, box(0.0, 0.01, 0.11, 0.04), "pvc")], fluid=fluid, tmax=0.05)
    text = text.replace('relativeweight="0.5"', 'relativeweight="2"')
    r, rows = run(tmp_path, text)
    assert rows["z"][-1] == pytest.approx(rows["z"][0], abs=1e-4)


def test_an_sph_run_without_a_speed_of_sound_is_refused(tmp_path):
    """No gravity and speedsystem auto: c0 = 0, which crashed (ZeroDivisionError) before; now exit 2
    saying what to set."""
    path = tmp_path / "CaseNoSound_Def.xml"
    path.write_text(case_xml([(1, box(0.0, 0.2, 0.05, 0.05), "pvc")], gravity=0.0, fixed_speed=False))
    r = CliRunner().invoke(main, ["run", str(path), "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and "the speed of sound c0 is 0 m/s" in r.output and "<speedsystem" in r.output


@pytest.mark.parametrize("algorithm", [1, 2])
def test_a_dem_run_resumes_bitwise(tmp_path, algorithm):
    """The DEM's Δt is the previous step's dt (Verlet) or the step's (Symplectic): nothing of its own
    in restart.h5, and a run interrupted at 0.05 s and resumed ends bitwise as one run to 0.1 s."""
    import h5py
    foot = '<drawpoint x="0.05" y="0" z="0.02" />'
    text = case_xml([(1, box(0.0, 0.03, 0.1, 0.08) + foot, "pvc")], tmax=0.1, tout=0.05).replace(
        '<parameter key="StepAlgorithm" value="2" />', f'<parameter key="StepAlgorithm" value="{algorithm}" />')
    case = tmp_path / "CaseDem_Def.xml"
    case.write_text(text)
    for out, tmax in (("a", "0.1"), ("b", "0.05")):
        r = CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path / out), "--threads", "1", "-q",
                                      "--tmax", tmax])
        assert r.exit_code == 0, r.output
    r = CliRunner().invoke(main, ["run", str(tmp_path / "b"), "--resume", "--tmax", "0.1", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output

    def state(d):
        with h5py.File(tmp_path / d / "restart.h5", "r") as f:
            o = np.argsort(f["state/idp"][...])
            return [f["state/pos"][...][o], f["state/vel"][...][o], f["bodies/pos"][...], f["bodies/vel"][...]]
    for x, y in zip(state("a"), state("b")):
        assert np.array_equal(x, y)
    rows = np.genfromtxt(tmp_path / "a" / "bodies.csv", delimiter=",", names=True, dtype=None, encoding=None)
    assert rows["vz"][-1] != 0.0                   # it is bouncing at 0.05 s


def test_the_pile_case_runs(tmp_path):
    """cases/dem2d/CaseDemPile2D (tools/bench_dem.py's scene): 200 bodies, no fluid; 0.02 s runs and the
    blocks fall freely (no contact yet: every body has gained g t of downward speed, to the file's digits)."""
    case = Path(__file__).resolve().parents[2] / "cases" / "dem2d" / "CaseDemPile2D_Def.xml"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(tmp_path / "out"), "--threads", "1", "-q",
                                  "--tmax", "0.02", "--tout", "0.02"])
    assert r.exit_code == 0, r.output
    rows = np.genfromtxt(tmp_path / "out" / "bodies.csv", delimiter=",", names=True, dtype=None, encoding=None)
    last = rows[rows["time"] == rows["time"].max()]
    assert len(last) == 200
    assert last["vz"] == pytest.approx(-9.81 * last["time"][0], rel=1e-7)


def test_dem_with_a_chrono_section_is_refused(tmp_path):
    """RigidAlgorithm 2 with a <special><chrono> section: DualSPHysics takes the chrono bodies under
    RigidAlgorithm 3 only, and the DEM and sphdvi's multibody engine would both put contacts on the
    bodies: exit 2 at gencase, naming the parameter."""
    chrono = ('<special><chrono><savedata value="0.01" /><schemescale value="1" />'
              '<bodyfloating id="box" mkbound="1" /></chrono></special>')
    text = case_xml([(1, box(0.0, 0.01, 0.11, 0.09), "pvc")]).replace("<execution>", "<execution>" + chrono)
    path = tmp_path / "CaseDemChrono_Def.xml"
    path.write_text(text)
    r = CliRunner().invoke(main, ["gencase", str(path), "-o", str(tmp_path / "g")])
    assert r.exit_code == 2 and "RigidAlgorithm 2 (DEM contacts) with a <special><chrono> section" in r.output
    assert "<parameter>" in r.output and "Traceback" not in r.output


def test_a_moving_wall_knocks_a_block_on(tmp_path):
    """No gravity: a steel wall (one column of particles, mkbound 2) moving at 0.3 m/s along +x (<mvrect>)
    meets a pvc block at rest 2 dp ahead of it. The contacts see the wall's own velocity (v_i − v_j), so
    the block leaves faster than the wall, at up to (1 + e) times its speed, and the wall does not stop."""
    wall = ('<setmkbound mk="2" /><drawbox><boxfill>solid</boxfill><point x="-0.02" y="-1" z="0.19" />'
            '<size x="0" y="2" z="0.07" /></drawbox>')
    motion = ('<motion><objreal ref="2"><begin mov="1" start="0" /><mvrect id="1" duration="1">'
              '<vel x="0.3" y="0" z="0" /></mvrect></objreal></motion>')
    text = case_xml([(1, box(0.0, 0.2, 0.05, 0.05), "pvc")], gravity=0.0, fluid=wall, tmax=0.12, tout=0.01,
                    links='<link mkbound="0" property="steel" /><link mkbound="2" property="steel" />')
    text = text.replace("</floatings>", "</floatings>" + motion)
    _, rows = run(tmp_path, text)
    assert rows["vx"][0] == 0.0
    assert 0.3 < rows["vx"][-1] < 0.6 and abs(rows["vz"][-1]) < 1e-6
