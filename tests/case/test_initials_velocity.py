"""Velocity profiles of ``<initials><velocity>`` and ``<special><initialize><fluidvelocity>``:
one reader for both (JDsInitializeOp_FluidVel::ReadXml: every attribute of the profile
required, one profile, distinct heights), and an item that selects no particle is a warning
(DualSPHysics reports "0 particles"), not an error."""
import re

import numpy as np
import pytest
from casetext import case_xml, write_case

from sphdvi.case.gencase import build_case
from sphdvi.errors import CaseError


def initials(profile: str) -> str:
    return f'\n<initials><velocity mkfluid="0"><direction x="1" y="0" z="0"/>{profile}</velocity></initials>'


def fluidvelocity(profile: str) -> str:
    return f'<initialize><fluidvelocity mkfluid="0"><direction x="1" y="0" z="0"/>{profile}</fluidvelocity></initialize>'


def build(tmp_path, **kw):
    return build_case(write_case(tmp_path, case_xml(dp="0.05", **kw)), str(tmp_path / "out"))


BAD = [('<velocity2 v="1" v2="2" z="0"/>', "<velocity2>: missing attribute 'z2'"),
       ('<velocity3 v="1" v2="2" z="0" z2="1" z3="2"/>', "<velocity3>: missing attribute 'v3'"),
       ('<velocity2 v="1" v2="2" z="0.5" z2="0.5"/>', "the heights z of <velocity2> repeat"),
       ('<velocity3 v="2" v2="1" v3="1" z="0" z2="0.15" z3="0.15"/>', "the heights z of <velocity3> repeat"),
       ('<velocity v="5"/><velocity2 v="1" v2="2" z="0" z2="0.3"/>', "<velocity2>: several velocity profiles"),
       ('', "missing velocity profile")]


@pytest.mark.parametrize("profile, message", BAD)
@pytest.mark.parametrize("where", ["initials", "fluidvelocity"])
def test_bad_profiles_are_case_errors_with_the_line(tmp_path, where, profile, message):
    """A missing attribute crashed gencase (KeyError), equal heights gave NaN velocities (or a
    least-squares parabola) and a second profile replaced the first, in <initials> only."""
    kw = {"casedef_extra": initials(profile)} if where == "initials" else {"special": fluidvelocity(profile)}
    with pytest.raises(CaseError, match=r"Case_Def.xml:\d+: .*" + re.escape(message)):
        build(tmp_path, **kw)


def test_linear_profile_of_initials(tmp_path):
    r = build(tmp_path, casedef_extra=initials('<velocity2 v="1" v2="2" z="0" z2="1"/>'))
    p = r.particles
    fluid = p["type"] == 3
    np.testing.assert_allclose(p["vel"][fluid, 0], 1 + p["pos"][fluid, 2], rtol=1e-12)


@pytest.mark.parametrize("where", ["initials", "fluidvelocity"])
def test_an_item_selecting_no_particle_is_a_warning(tmp_path, where):
    box = '<onlypos><posmin x="5" y="-1" z="0"/><posmax x="6" y="1" z="1"/></onlypos>'
    if where == "initials":
        kw = {"casedef_extra": f'\n<initials><velocity mkfluid="0" x="1" y="0" z="0">{box}</velocity></initials>'}
    else:
        kw = {"special": f'<initialize><fluidvelocity mkfluid="0">{box}<direction x="1" y="0" z="0"/>'
                         '<velocity v="1"/></fluidvelocity></initialize>'}
    r = build(tmp_path, **kw)
    tag = "velocity" if where == "initials" else "fluidvelocity"
    assert [w for w in r.warnings if "selects no particles" in w] == [
        w for w in r.warnings if re.search(rf"Case_Def.xml:\d+: warning: <{tag}>: it selects no particles .*onlypos", w)]
    assert len([w for w in r.warnings if "selects no particles" in w]) == 1
    assert not r.particles["vel"].any()
