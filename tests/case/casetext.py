"""Small case files for tests, built from pieces so each test changes one thing."""
from __future__ import annotations

CONSTANTS = """
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>"""

TANK_2D = """
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="-1" z="0" /><size x="1" y="2" z="2" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" /><size x="4" y="2" z="3" /></drawbox>"""


def case_xml(*, dp="0.02", pointmin=("-1", "0", "-1"), pointmax=("4.5", "0", "3.5"), commands=TANK_2D,
             constants=CONSTANTS, casedef_extra="", special="", parameters="", predefinition="",
             mkconfig='<mkconfig boundcount="240" fluidcount="9" />', lists="") -> str:
    pre = f"<predefinition>{predefinition}</predefinition>" if predefinition else ""
    return f"""<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>{constants}
        {mkconfig}
        <geometry>
            {pre}
            <definition dp="{dp}">
                <pointmin x="{pointmin[0]}" y="{pointmin[1]}" z="{pointmin[2]}" />
                <pointmax x="{pointmax[0]}" y="{pointmax[1]}" z="{pointmax[2]}" />
            </definition>
            <commands>{lists}
                <mainlist>{commands}
                </mainlist>
            </commands>
        </geometry>{casedef_extra}
    </casedef>
    <execution>
        <special>{special}</special>
        <parameters>{parameters}</parameters>
    </execution>
</case>
"""


def write_case(tmp_path, text: str, name: str = "Case_Def.xml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)
