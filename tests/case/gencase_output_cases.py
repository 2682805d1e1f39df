"""GenCase output files (case files GenCase wrote, with its ``<particles>`` and ``<constants>``
record of what it drew) from public repositories, as test data for
``test_gencase_outputs_counts.py``.

Each text is the file with its comments, its ``comment=""`` attributes, its disabled entries
(``#Key`` parameters, ``_name`` elements) and the parameters left at DualSPHysics's defaults
dropped; the geometry, ``<constantsdef>``, ``<special>`` sections, ``<particles>`` and
``<constants>`` are kept as GenCase wrote them. The tests parse the record from the text itself.
"""

#: DualSPHysics/DualSPHysics examples/others/TimeOut/Dam2d.xml, GenCase4 v4.0.059 (29-12-2017):
#: 2-D dam break with a <timeout> table whose lines carry '%' remarks as element text
DAM2D_TIMEOUT = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.059 (29-12-2017)" date="20-02-2018 04:28:26">
    <casedef>
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="10" />
        <geometry>
            <definition dp="0.02" units_comment="metres (m)">
                <pointmin x="-1" y="0" z="-1" />
                <pointmax x="4.5" y="0" z="3.5" />
            </definition>
            <commands>
                <mainlist>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0" y="-1" z="0" />
                        <size x="1" y="2" z="2" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="-1" z="0" />
                        <size x="4" y="2" z="3" />
                    </drawbox>
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <special>
            <timeout>
                <tout time="0.05" timeout="0.01" />  % First output at t=0.05s. Next, output files are stored at 0.01s.
                <tout time="0.1" timeout="0.07" />   % Since t=0.1s, output files are stored at 0.07s.
                <tout time="0.2" timeout="0.001" />  % Since t=0.2s, output files are stored at 0.001s.
                <tout time="0.3" timeout="0.01" />   % Since t=0.3s, output files are stored at 0.01s.
            </timeout>
        </special>
        <parameters>
            <parameter key="PosDouble" value="1" />
            <parameter key="Visco" value="0.02" />
            <parameter key="TimeMax" value="0.72" />
            <parameter key="TimeOut" value="0.01" />
            <parameter key="IncZ" value="0.5" />
        </parameters>
        <particles np="5501" nb="501" nbf="501" mkboundfirst="11" mkfluidfirst="1">
            <_summary>
                <fixed count="501" id="0-500" mkcount="1" mkvalues="11" />
                <fluid count="5000" id="501-5500" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="11" begin="0" count="501" />
            <fluid mkfluid="0" mk="1" begin="501" count="5000" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.02" units_comment="metres (m)" />
            <h value="2.8284271247E-002" units_comment="metres (m)" />
            <b value="1.1099314286E+006" units_comment="Pascal (Pa)" />
            <massbound value="4.0000000000E-001" units_comment="kg" />
            <massfluid value="4.0000000000E-001" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""

#: DualSPHysics/DualSPHysics examples/others/GaugeSystem/GMaxZ_Dam2d.xml, GenCase4 v4.0.059
#: (29-12-2017): the same dam break with an swl gauge and a maxz gauge
GMAXZ_DAM2D = DAM2D_TIMEOUT.replace("20-02-2018 04:28:26", "15-02-2018 18:24:10").replace(
    DAM2D_TIMEOUT[DAM2D_TIMEOUT.index("        <special>"):DAM2D_TIMEOUT.index("        <particles")],
    """        <special>
            <gauges>
                <default>
                    <savevtkpart value="true" />
                    <output value="true" />
                </default>
                <swl name="Swl_x09">
                    <pointdp coefdp="0.5" units_comment="m" />
                    <point0 x="0.9" y="0" z="0" units_comment="m" />
                    <point2 x="0.9" y="0" z="2.1" units_comment="m" />
                </swl>
                <maxz name="MaxX_x09">
                    <point0 x="0.9" y="0" z="0" units_comment="m" />
                    <height value="2.1" units_comment="m" />
                    <distlimit coefdp="2" />
                </maxz>
            </gauges>
        </special>
        <parameters>
            <parameter key="Visco" value="0.02" />
            <parameter key="TimeMax" value="0.72" />
            <parameter key="TimeOut" value="0.01" />
            <parameter key="IncZ" value="0.5" />
        </parameters>
""")

#: DualSPHysics/DualSPHysics examples/others/GaugeSystem/GVel_Dam2d.xml, GenCase4 v4.0.059
#: (29-12-2017): the same dam break with two velocity gauges and a <simulationdomain>
GVEL_DAM2D = DAM2D_TIMEOUT.replace("20-02-2018 04:28:26", "15-02-2018 14:03:19").replace(
    DAM2D_TIMEOUT[DAM2D_TIMEOUT.index("        <special>"):DAM2D_TIMEOUT.index("        <particles")],
    """        <special>
            <gauges>
                <default>
                    <savevtkpart value="false" />
                    <output value="true" />
                    <outputdt value="0" units_comment="s" />
                    <outputtime start="0" end="10" units_comment="s" />
                </default>
                <velocity name="VelPt1">
                    <savevtkpart value="true" />
                    <computedt value="0.01" units_comment="s" />
                    <computetime start="0.1" end="0.11" units_comment="s" />
                    <output value="true" />
                    <outputdt value="0" units_comment="s" />
                    <outputtime start="0" end="10" units_comment="s" />
                    <point x="0.9" y="0" z="0.1" units_comment="m" />
                </velocity>
                <velocity name="VelPt2">
                    <savevtkpart value="true" />
                    <output value="false" />
                    <point x="1.2" y="0" z="0.1" units_comment="m" />
                </velocity>
            </gauges>
        </special>
        <parameters>
            <parameter key="Visco" value="0.02" />
            <parameter key="TimeMax" value="0.72" />
            <parameter key="TimeOut" value="0.01" />
            <simulationdomain>
                <posmin x="default" y="default" z="default" />
                <posmax x="default" y="default" z="default + 50%" />
            </simulationdomain>
        </parameters>
""")

#: DualSPHysics/DualSPHysics examples/others/SaveDt/Case5aSvdt_8k.xml (no app attribute: an
#: output GenCase4 wrote, edited by hand; coefh 0.866025): the 3-D dam break with a building, a
#: <setmkvoid> cut and <savedt>
CASE5A_SVDT_8K = """<?xml version="1.0" encoding="UTF-8" ?>
<case>
    <casedef>
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="0.866025" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="10" />
        <geometry>
            <definition dp="0.0272" units_comment="metres (m)">
                <pointmin x="-0.05" y="-0.05" z="-0.05" />
                <pointmax x="2" y="1" z="1" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>dp | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="0.4" y="0.67" z="0.3" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="1.6" y="0.67" z="0.4" />
                    </drawbox>
                    <setmkvoid />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0.9" y="0.24" z="0" />
                        <size x="0.12" y="0.12" z="0.45" />
                    </drawbox>
                    <setmkbound mk="1" />
                    <drawbox>
                        <boxfill>top | left | right | front | back</boxfill>
                        <point x="0.9" y="0.24" z="0" />
                        <size x="0.12" y="0.12" z="0.45" />
                    </drawbox>
                    <shapeout file="" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <special>
            <savedt>
                <start value="0.01" />
                <finish value="1" />
                <interval value="0.005" />
                <fullinfo value="1" />
                <alldt value="1" />
            </savedt>
        </special>
        <parameters>
            <parameter key="PosDouble" value="1" />
            <parameter key="Visco" value="0.25" />
            <parameter key="TimeMax" value="1.2" />
            <parameter key="TimeOut" value="0.01" />
            <parameter key="IncZ" value="0.1" />
        </parameters>
        <particles np="8041" nb="4246" nbf="4246" mkboundfirst="11" mkfluidfirst="1">
            <fixed mkbound="0" mk="11" begin="0" count="3965" />
            <fixed mkbound="1" mk="12" begin="3965" count="281" />
            <fluid mkfluid="0" mk="1" begin="4246" count="3795" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.0272" units_comment="metres (m)" />
            <h value="4.0799980977E-002" units_comment="metres (m)" />
            <b value="1.5247542857E+005" units_comment="metres (m)" />
            <massbound value="2.0123648000E-002" units_comment="kg" />
            <massfluid value="2.0123648000E-002" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""

#: DualSPHysics/DualSPHysics examples/others/GaugeSystem/WallRegAwas2.xml, GenCase4 v4.0.059
#: (29-12-2017): 2-D wave flume, a piston (moving, mkbound 10) with AWAS, fillbox water
WALLREGAWAS2 = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.059 (29-12-2017)" date="19-02-2018 18:54:53">
    <casedef>
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0" y="0" z="-9.81" />
            <cflnumber value="0.2" />
            <hswl value="0" auto="true" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="1.2" />
            <gamma value="7" />
            <rhop0 value="1000" />
        </constantsdef>
        <mkconfig boundcount="230" fluidcount="10">
            <mkorientfluid mk="0" orient="Xyz" />
        </mkconfig>
        <geometry>
            <definition dp="0.006">
                <pointmin x="-1" y="1" z="-1" />
                <pointmax x="5" y="1" z="5" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>real | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkbound mk="10" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="-0.014" y="0" z="0" />
                        <size x="0.014" y="2" z="0.6" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | right</boxfill>
                        <point x="-0.2" y="0" z="0" />
                        <size x="3.2" y="2" z="0.6" />
                    </drawbox>
                    <setmkfluid mk="0" />
                    <fillbox x="0.25" y="1" z="0.05">
                        <modefill>void</modefill>
                        <point x="-1" y="0" z="-1" />
                        <size x="6" y="2" z="1.268" />
                    </fillbox>
                    <shapeout file="" reset="true" />
                </mainlist>
            </commands>
        </geometry>
        <motion>
            <objreal ref="10">
                <begin mov="1" start="0" />
                <mvnull id="1" />
            </objreal>
        </motion>
    </casedef>
    <execution>
        <special>
            <wavepaddles>
                <piston>
                    <mkbound value="10" />
                    <depth value="0.266" />
                    <pistondir x="1" y="0" z="0" />
                    <waveorder value="1" />
                    <waveheight value="0.1" />
                    <waveperiod value="1.3" />
                    <ramp value="1" />
                    <awas_zsurf>
                        <startawas value="2.6" />
                        <swl value="0.266" />
                        <gaugex valuedp="5" />
                        <gaugey value="1" />
                        <gaugezmin value="0.1" />
                        <gaugezmax value="0.4" />
                        <gaugedp value="0.1" />
                    </awas_zsurf>
                </piston>
            </wavepaddles>
        </special>
        <parameters>
            <parameter key="PosDouble" value="1" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.01" />
            <parameter key="ViscoBoundFactor" value="0" />
            <parameter key="TimeMax" value="20" />
            <parameter key="TimeOut" value="0.02" />
            <parameter key="IncZ" value="0" />
        </parameters>
        <particles np="22492" nb="1035" nbf="635" mkboundfirst="11" mkfluidfirst="1">
            <_summary>
                <fixed count="635" id="0-634" mkcount="1" mkvalues="11" />
                <moving count="400" id="635-1034" mkcount="1" mkvalues="21" />
                <fluid count="21457" id="1035-22491" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="11" begin="0" count="635" />
            <moving mkbound="10" mk="21" begin="635" count="400" refmotion="0" />
            <fluid mkfluid="0" mk="1" begin="1035" count="21457" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.006" units_comment="metres (m)" />
            <h value="1.0182337649E-002" units_comment="metres (m)" />
            <b value="1.4126400000E+005" units_comment="Pascal (Pa)" />
            <massbound value="3.6000000000E-002" units_comment="kg" />
            <massfluid value="3.6000000000E-002" units_comment="kg" />
        </constants>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" />
                <mvnull id="1" />
            </objreal>
        </motion>
    </execution>
</case>
"""

#: Otor123/DualSPHysics examples/main/01_DamBreak/CaseDambreakVal2D.xml, GenCase v5.4.354.01
#: (07-04-2025): despite its name, GenCase's output of the 3-D CaseDambreak geometry (a user ran
#: CaseDambreak_Def under that name); the same counts as v5.0.222's CaseDambreak_out
CASEDAMBREAK_V54 = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase v5.4.354.01 (07-04-2025)" date="25-07-2025 15:35:48">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <rhopgradient value="2" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.0085" units_comment="metres (m)">
                <pointmin x="-0.05" y="-0.05" z="-0.05" />
                <pointmax x="2" y="1" z="1" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>dp | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="0.4" y="0.67" z="0.3" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="1.6" y="0.67" z="0.4" />
                    </drawbox>
                    <shapeout file="Box" />
                    <setmkvoid />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0.9" y="0.24" z="0" />
                        <size x="0.12" y="0.12" z="0.45" />
                    </drawbox>
                    <setmkbound mk="1" />
                    <drawbox>
                        <boxfill>top | left | right | front | back</boxfill>
                        <point x="0.9" y="0.24" z="0" />
                        <size x="0.12" y="0.12" z="0.45" />
                    </drawbox>
                    <setmkbound mk="10" />
                    <drawbox>
                        <boxfill>left</boxfill>
                        <point x="0.9" y="0.24" z="0" />
                        <size x="0.12" y="0.12" z="0.45" />
                    </drawbox>
                    <shapeout file="Building" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="1" />
            <parameter key="Kernel" value="1" />
            <parameter key="Visco" value="0.1" />
            <parameter key="DensityDT" value="2" />
            <parameter key="TimeMax" value="1.6" />
            <parameter key="TimeOut" value="0.01" />
            <simulationdomain>
                <posmin x="default" y="default" z="default" />
                <posmax x="default" y="default" z="default + 50%" />
            </simulationdomain>
        </parameters>
        <particles np="171496" nb="43186" nbf="43186" mkboundfirst="10" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="0.001" y="0.001" z="0.001" />
                    <posmax x="1.599" y="0.6725" z="0.4515" />
                </positions>
                <fixed count="43186" id="0-43185" mkcount="3" mkvalues="10-11,20" />
                <fluid count="128310" id="43186-171495" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="10" begin="0" count="39993" />
            <fixed mkbound="1" mk="11" begin="39993" count="2383" />
            <fixed mkbound="10" mk="20" begin="42376" count="810" />
            <fluid mkfluid="0" mk="1" begin="43186" count="128310" />
        </particles>
        <constants>
            <data2d value="false" />
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.0085" units_comment="metres (m)" />
            <h value="0.014722431864" units_comment="metres (m)" />
            <b value="162005.14286" units_comment="Pascal (Pa)" />
            <massbound value="0.000614125" units_comment="kg" />
            <massfluid value="0.000614125" units_comment="kg" />
        </constants>
        <uservars>
            <varnum name="VResId" value="0" />
        </uservars>
        <motion />
        <vtkout mkboundfirst="10" mkfluidfirst="1">
            <vtkfile name="CaseDambreakVal2D_Box_Dp.vtk" mk="10" mkbound="0" />
            <vtkfile name="CaseDambreakVal2D_Building_Dp.vtk" mk="11,20" mkbound="1,10" />
        </vtkout>
    </execution>
</case>
"""

#: DualSPHysics/DualSPHysics examples/others/RotatedBox/RotatedBox.xml, GenCase4 v4.0.068
#: (27-04-2018): a box drawn under <rotateline ang="40"> (mkbound 2) next to one drawn unrotated and
#: then turned by <initials><rotateaxis> (mkbound 3)
ROTATEDBOX = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.068 (27-04-2018)" date="07-05-2018 12:03:12">
    <casedef>
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="15" />
            <speedsound value="0" auto="true" />
            <coefh value="1.0" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="3" />
        <geometry>
            <definition dp="0.005" units_comment="metres (m)">
                <pointmin x="-0.2" y="-0.2" z="-0.2" />
                <pointmax x="3" y="0.7" z="0.3" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>real | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0" y="0" z="0" />
                        <size x="0.25" y="0.5" z="0.1" />
                    </drawbox>
                    <setmkbound mk="2" />
                    <rotateline ang="40">
                        <point x="0.45" y="0.145" z="0" />
                        <point x="0.45" y="0.145" z="1" />
                    </rotateline>
                    <drawbox>
                        <boxfill>all ^ top ^ bottom</boxfill>
                        <point x="0.45" y="0.04" z="0" />
                        <size x="0.05" y="0.21" z="0.04" />
                    </drawbox>
                    <matrixreset />
                    <setmkbound mk="3" />
                    <drawbox>
                        <boxfill>all ^ top ^ bottom</boxfill>
                        <point x="0.45" y="0.25" z="0" />
                        <size x="0.05" y="0.21" z="0.04" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>left | front | back</boxfill>
                        <point x="0" y="0.0" z="0" />
                        <size x="0.8" y="0.5" z="0.15" />
                    </drawbox>
                    <setmkbound mk="1" />
                    <drawbox>
                        <boxfill>bottom</boxfill>
                        <point x="0" y="0.0" z="0" />
                        <size x="0.8" y="0.5" z="0.15" />
                    </drawbox>
                </mainlist>
            </commands>
        </geometry>
        <initials>
            <rotateaxis mkbound="3" angle="-40" anglesunits="degrees">
                <axisp1 x="0.45" y="0.355" z="0" />
                <axisp2 x="0.45" y="0.355" z="1" />
            </rotateaxis>
        </initials>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.05" />
            <parameter key="ViscoBoundFactor" value="0" />
            <parameter key="TimeMax" value="1.2" />
            <parameter key="TimeOut" value="0.01" />
            <parameter key="IncZ" value="0" />
        </parameters>
        <particles np="129683" nb="30683" nbf="30683" mkboundfirst="4" mkfluidfirst="1">
            <_summary>
                <fixed count="30683" id="0-30682" mkcount="4" mkvalues="4-7" />
                <fluid count="99000" id="30683-129682" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="4" begin="0" count="12630" />
            <fixed mkbound="1" mk="5" begin="12630" count="16261" />
            <fixed mkbound="2" mk="6" begin="28891" count="960" />
            <fixed mkbound="3" mk="7" begin="29851" count="832" />
            <fluid mkfluid="0" mk="1" begin="30683" count="99000" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.005" units_comment="metres (m)" />
            <h value="8.6602540378E-03" units_comment="metres (m)" />
            <b value="2.9955535714E+04" units_comment="Pascal (Pa)" />
            <massbound value="1.2500000000E-04" units_comment="kg" />
            <massfluid value="1.2500000000E-04" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""

#: yzhao469/DualSPHysicsAgent_v1 examples/others/FtRestrictions/FtSloshing.xml (the DualSPHysics
#: v5.4 package tree), GenCase4 v4.0.092 (26-03-2019), a DesignSPHysics case: a floating box drawn
#: before any <setdrawmode>; GenCase wrote mkboundfirst="11" with fluidcount="9"
FTSLOSHING = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.092 (26-03-2019)" date="04-04-2019 01:20:26">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="1000" />
            <hswl value="0.4" auto="false" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <coefh value="1" />
            <cflnumber value="0.2" />
            <h value="0" auto="true" units_comment="metres (m)" />
            <b value="0" auto="true" units_comment="metres (m)" />
            <massbound value="0" auto="true" units_comment="kg" />
            <massfluid value="0" auto="true" units_comment="kg" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.01" units_comment="metres (m)">
                <pointmin x="-2" y="0" z="-1" />
                <pointmax x="2" y="0" z="2" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>dp | bound</setshapemode>
                    <setmkbound mk="0" />
                    <drawbox objname="Tank">
                        <boxfill>all</boxfill>
                        <point x="-0.7" y="-0.1" z="0" />
                        <size x="1.4" y="0.2" z="0.9" />
                    </drawbox>
                    <setmkbound mk="1" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0" y="-0.1" z="0.35" />
                        <size x="0.2" y="0.2" z="0.1" />
                    </drawbox>
                    <setmkfluid mk="0" />
                    <fillbox x="0" y="0" z="0.1">
                        <modefill>void</modefill>
                        <point x="-2" y="-0.1" z="-1" />
                        <size x="4" y="0.2" z="1.4" />
                    </fillbox>
                    <shapeout file="" />
                </mainlist>
            </commands>
        </geometry>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" />
                <mvrectsinu id="1" duration="100">
                    <freq x="0.5" y="0.0" z="0.0" />
                    <ampl x="0.07" y="0.0" z="0.0" />
                    <phase x="0.0" y="0.0" z="0.0" />
                </mvrectsinu>
            </objreal>
        </motion>
        <floatings>
            <floating mkbound="1" relativeweight="0.5" />
        </floatings>
    </casedef>
    <execution>
        <special />
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.05" />
            <parameter key="DensityDT" value="1" />
            <parameter key="TimeMax" value="4" />
            <parameter key="TimeOut" value="0.01" />
            <simulationdomain>
                <posmin x="-2" y="-0.1" z="-0.1" />
                <posmax x="2" y="0.1" z="1" />
            </simulationdomain>
        </parameters>
        <particles np="5976" nb="631" nbf="0" mkboundfirst="11" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="-0.7" y="0" z="0" />
                    <posmax x="0.7" y="0" z="0.9" />
                </positions>
                <moving count="460" id="0-459" mkcount="1" mkvalues="11" />
                <floating count="171" id="460-630" mkcount="1" mkvalues="12" />
                <fluid count="5345" id="631-5975" mkcount="1" mkvalues="1" />
            </_summary>
            <moving mkbound="0" mk="11" begin="0" count="460" refmotion="0" />
            <floating mkbound="1" mk="12" begin="460" count="171">
                <massbody value="8.55" units_comment="kg" />
                <masspart value="0.05" units_comment="kg" />
                <center x="0.1" y="0" z="0.4" units_comment="metres (m)" />
                <inertia units_comment="kg*m^2">
                    <values v11="0.0057" v12="0" v13="6.50521e-20" />
                    <values v21="0" v22="0.03135" v23="0" />
                    <values v31="6.50521e-20" v32="0" v33="0.02565" />
                </inertia>
            </floating>
            <fluid mkfluid="0" mk="1" begin="631" count="5345" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.01" units_comment="metres (m)" />
            <h value="1.4142135624E-02" units_comment="metres (m)" />
            <b value="2.2422857143E+05" units_comment="Pascal (Pa)" />
            <massbound value="1.0000000000E-01" units_comment="kg" />
            <massfluid value="1.0000000000E-01" units_comment="kg" />
        </constants>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" />
                <mvrectsinu id="1" duration="100" anglesunits="degrees">
                    <freq x="0.5" y="0" z="0" units_comment="1/s" />
                    <ampl x="0.07" y="0" z="0" units_comment="metres (m)" />
                    <phase x="0" y="0" z="0" units_comment="degrees" />
                </mvrectsinu>
            </objreal>
        </motion>
        <vtkout mkboundfirst="11" mkfluidfirst="1">
            <vtkfile name="FtSloshing__Dp.vtk" mk="11-12" mkbound="0-1" />
        </vtkout>
    </execution>
</case>
"""

#: yzhao469/DualSPHysicsAgent_v1 examples/others/Variables/GenericWaveTank.xml, GenCase
#: v5.0.165 (24-03-2020): a 2-D flume built with user variables, a <drawextrude> beach of 4 layers
GENERICWAVETANK = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase v5.0.165 (24-03-2020)" date="24-03-2020 20:29:27">
    <casedef requiredversion="v5.0.165">
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0.0" y="0.0" z="-9.8065" />
            <rhop0 value="1000.0" />
            <hswl value="0.0" auto="true" />
            <gamma value="7.0" />
            <speedsystem value="0.0" auto="true" />
            <coefsound value="20.0" />
            <speedsound value="0.0" auto="true" />
            <coefh value="1.2" />
            <cflnumber value="0.2" />
            <h value="0.0" auto="true" units_comment="metres (m)" />
            <b value="0.0" auto="true" units_comment="Pascal (Pa)" />
            <massbound value="0" auto="true" units_comment="kg" />
            <massfluid value="0" auto="true" units_comment="kg" />
        </constantsdef>
        <mkconfig boundcount="241" fluidcount="2" />
        <geometry>
            <predefinition>
                <newvarcte case3d="false" _rem="Defines case 3D or 2D" />
                <newvarcte use_awas="true" _rem="Activates the use of AWAS" />
                <newvarcte use_damping="true" _rem="Activates the use of Damping" />
                <newvarcte use_beach="true" _rem="Creates an absorption beach" />
                <newvarcte depth="2.6" _rem="Water level" />
                <newvarcte wperiod="2.0" wheight="0.14" _rem="Wave parameters: Period and Wave height" />
                <newvarcte ang="25" _rem="Beach angle (if not beach ang = 90)" />
                <newvarcte pt="5" _rem="Piston thickness in particles (pt)" />
                <newvarcte n_up="1" n_down="0" _rem="Number of wave length upstream and downstream" />
                <newvarcte tankw="1.0" _rem="Basin (tank) width for 3-D cases" />
                <newvarcte wlen="wavelength(-Gravity_z,depth,wperiod)" _rem="Wave length" _print="1" />
                <newvarcte sk="wlen*0.3" _rem="Maximum stroke displacement" _print="1" />
                <newvarcte tankh="depth+wheight*2" _rem="Basin (tank) height" _print="1" />
                <newvarcte tankx="wlen*(n_up+1+n_down)" _rem="Basin (tank) length" _print="1" />
                <newvarcte dlen="eval(use_beach,tankh/tandg(ang),wlen*0.5)" _rem="Beach or damping zone length" _print="1" />
                <newvarcte tankxtot="sk+tankx+dlen" _rem="Total basin (tank) length" _print="1" />
                <newvarcte modelx="(n_up+0.5)*wlen" _rem="Distance between wave paddle and model center" _print="1" />
            </predefinition>
            <definition dp="0.02" units_comment="metres (m)">
                <pointmin x="#-modelx-sk-Dp" y="#eval(case3d,-tankw/2-Dp*pt,0)" z="#-depth-Dp*pt" />
                <pointmax x="#-modelx+tankxtot" y="#eval(case3d,tankw/2+Dp*pt,0)" z="#wheight*2+Dp" />
            </definition>
            <commands>
                <list name="TankWall" printcall="false">
                    <setshapemode if="#walln>0">bound</setshapemode>
                    <drawpolygon>
                        <point x="#-sk" y="#wallx" z="#-dpt" />
                        <point x="#tankx" y="#wallx" z="#-dpt" />
                        <point x="#tankx+eval(use_beach,(dlen+dpt)/2,dlen+dpt)" y="#wallx" z="#eval(use_beach,tankh/2,-dpt)" />
                        <point x="#tankx+dlen+dpt" y="#wallx" z="#tankh" />
                        <point x="#-sk" y="#wallx" z="#tankh" />
                    </drawpolygon>
                    <setvar wallx="wallx+wallix" />
                    <setvar walln="walln+1" />
                    <setshapemode>actual | bound</setshapemode>
                </list>
                <mainlist>
                    <exportvar vars="depth,wperiod,wheight,use_awas,use_damping,tankx,dlen,modelx" />
                    <abort if="use_beach @@ (ang<2 || ang>90)" text="Beach angle (#ang#) is not in the range [1-90].\\n It is invalid." />
                    <newvarcte Ur="(wheight*pow(wlen,2))/(pow(depth,2))" _rem="Ursell number" />
                    <printf text="==>> Wave steepness parameter..: #wheight/wlen#" />
                    <printf text="==>> Wave shallowness parameter: #depth/wlen#" />
                    <printf text="==>> Ursell number.............: #Ur#" />
                    <newvarcte dpt="(pt-1)*Dp" _rem="Piston thickness in metres" />
                    <setshapemode>actual | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <move x="#-modelx" y="0" z="#-depth" />
                    <setmkbound mk="2" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="#-dpt" y="#-0.5*tankw" z="0" />
                        <size x="#dpt" y="#tankw" z="#tankh" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawextrude closed="false">
                        <point x="#-sk" y="#-0.5*tankw" z="0" />
                        <point x="#tankx" y="#-0.5*tankw" z="0" />
                        <point x="#tankx+eval(use_beach,dlen/2,dlen)" y="#-0.5*tankw" z="#eval(use_beach,tankh/2,0)" />
                        <point x="#tankx+dlen" y="#-0.5*tankw" z="#tankh" />
                        <extrude x="0" y="#tankw" z="0" />
                        <layers vdp="0*,-1,-2,-3" />
                    </drawextrude>
                    <newvar wallx="-0.5*tankw" wallix="-Dp" walln="0" />
                    <runlist name="TankWall" times="#eval(case3d,pt,0)" />
                    <setvar wallx="0.5*tankw" wallix="Dp" walln="0" />
                    <runlist name="TankWall" times="#eval(case3d,pt,0)" />
                    <setmkfluid mk="0" />
                    <fillbox x="#0.5*wlen" y="0" z="#0.5*depth">
                        <modefill>void</modefill>
                        <point x="0" y="#-0.5*tankw" z="0" />
                        <size x="#tankxtot+1" y="#tankw" z="#depth" />
                    </fillbox>
                    <matrixreset />
                    <setmkbound mk="1" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="-0.3" y="#-0.2*tankw" z="-0.2" />
                        <size x="0.6" y="#0.4*tankw" z="0.4" />
                    </drawbox>
                    <shapeout file="" />
                </mainlist>
            </commands>
        </geometry>
        <motion>
            <objreal ref="2">
                <begin mov="1" start="0" />
                <mvnull id="1" />
            </objreal>
        </motion>
    </casedef>
    <execution>
        <special>
            <wavepaddles>
                <piston>
                    <mkbound value="2" />
                    <start value="0" />
                    <duration value="0.0" />
                    <depth value="#depth" />
                    <pistondir x="1.0" y="0.0" z="0.0" />
                    <waveorder value="2" />
                    <waveheight value="#wheight" />
                    <waveperiod value="#wperiod" />
                    <phase value="0.0" />
                    <ramp value="1.0" />
                    <savemotion xpos="#modelx" zpos="-0.15" />
                    <awas_zsurf active="#use_awas">
                        <startawas value="#wperiod" />
                        <swl value="0" />
                        <elevation value="2" />
                        <gaugey value="0" />
                        <gaugezmin value="#-2*wheight" />
                        <gaugezmax value="#2*wheight" />
                        <gaugedp value="0.25" />
                        <savedata value="0" />
                        <limitace value="2" />
                    </awas_zsurf>
                </piston>
            </wavepaddles>
            <damping active="#use_damping">
                <dampingzone>
                    <limitmin x="#tankx-modelx" y="0" z="0" />
                    <limitmax x="#tankx+dlen-modelx" y="0" z="0" />
                    <overlimit value="1" />
                    <redumax value="10" />
                    <factorxyz x="1" y="1" z="1" />
                </dampingzone>
            </damping>
        </special>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.01" />
            <parameter key="ViscoBoundFactor" value="0" />
            <parameter key="DensityDT" value="3" />
            <parameter key="TimeMax" value="10.0" />
            <parameter key="TimeOut" value="0.05" />
            <simulationdomain>
                <posmin x="default" y="default" z="default" />
                <posmax x="default" y="default" z="default" />
            </simulationdomain>
        </parameters>
        <particles np="102780" nb="5658" nbf="4938" mkboundfirst="3" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="-11.1243" y="0" z="-2.66" />
                    <posmax x="9.2957" y="0" z="0.28" />
                </positions>
                <fixed count="4938" id="0-4937" mkcount="2" mkvalues="3-4" />
                <moving count="720" id="4938-5657" mkcount="1" mkvalues="5" />
                <fluid count="97122" id="5658-102779" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="3" begin="0" count="4287" />
            <fixed mkbound="1" mk="4" begin="4287" count="651" />
            <moving mkbound="2" mk="5" begin="4938" count="720" refmotion="0" />
            <fluid mkfluid="0" mk="1" begin="5658" count="97122" />
        </particles>
        <constants>
            <data2d value="true" />
            <data2dposy value="0" units_comment="metres (m)" />
            <gravity x="0" y="0" z="-9.8065" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.02" units_comment="metres (m)" />
            <h value="3.3941125497E-02" units_comment="metres (m)" />
            <b value="1.4345508571E+06" units_comment="Pascal (Pa)" />
            <massbound value="4.0000000000E-01" units_comment="kg" />
            <massfluid value="4.0000000000E-01" units_comment="kg" />
        </constants>
        <uservars>
            <varnum name="depth" value="2.6" />
            <varnum name="dlen" value="6.17618" />
            <varnum name="modelx" value="9.27025" />
            <varnum name="tankx" value="12.3603" />
            <varnum name="use_awas" value="1" />
            <varnum name="use_damping" value="1" />
            <varnum name="wheight" value="0.14" />
            <varnum name="wperiod" value="2" />
        </uservars>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" />
                <mvnull id="1" />
            </objreal>
        </motion>
        <vtkout mkboundfirst="3" mkfluidfirst="1">
            <vtkfile name="GenericWaveTank__Actual.vtk" mk="3-5" mkbound="0-2" />
        </vtkout>
    </execution>
</case>
"""


#: DualSPHysics's examples/main/01_DamBreak/CaseDambreak_out/CaseDambreak.xml, written by GenCase
#: v5.0.222 (yzhao469/DualSPHysicsAgent_v1 holds the package's tree with this output); comments and
#: the parameters left at their defaults dropped, the record (<particles>, <constants>, <vtkout>) kept
CASEDAMBREAK_OUT = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase v5.0.222 (16-11-2020)" date="18-11-2025 16:36:46">
    <casedef>
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
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.0085" units_comment="metres (m)">
                <pointmin x="-0.05" y="-0.05" z="-0.05" />
                <pointmax x="2" y="1" z="1" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>dp | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkfluid mk="0" />
                    <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0" /><size x="0.4" y="0.67" z="0.3" /></drawbox>
                    <setmkbound mk="0" />
                    <drawbox><boxfill>bottom | left | right | front | back</boxfill><point x="0" y="0" z="0" /><size x="1.6" y="0.67" z="0.4" /></drawbox>
                    <shapeout file="Box" />
                    <setmkvoid />
                    <drawbox><boxfill>solid</boxfill><point x="0.9" y="0.24" z="0" /><size x="0.12" y="0.12" z="0.45" /></drawbox>
                    <setmkbound mk="1" />
                    <drawbox><boxfill>top | left | right | front | back</boxfill><point x="0.9" y="0.24" z="0" /><size x="0.12" y="0.12" z="0.45" /></drawbox>
                    <setmkbound mk="10" />
                    <drawbox><boxfill>left</boxfill><point x="0.9" y="0.24" z="0" /><size x="0.12" y="0.12" z="0.45" /></drawbox>
                    <shapeout file="Building" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="1" />
            <parameter key="Kernel" value="1" />
            <parameter key="Visco" value="0.1" />
            <parameter key="DensityDT" value="2" />
            <parameter key="TimeMax" value="1.6" />
            <parameter key="TimeOut" value="0.01" />
            <simulationdomain>
                <posmin x="default" y="default" z="default" />
                <posmax x="default" y="default" z="default + 50%" />
            </simulationdomain>
        </parameters>
        <particles np="171496" nb="43186" nbf="43186" mkboundfirst="10" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="0.001" y="0.001" z="0.001" />
                    <posmax x="1.599" y="0.6725" z="0.4515" />
                </positions>
                <fixed count="43186" id="0-43185" mkcount="3" mkvalues="10-11,20" />
                <fluid count="128310" id="43186-171495" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="10" begin="0" count="39993" />
            <fixed mkbound="1" mk="11" begin="39993" count="2383" />
            <fixed mkbound="10" mk="20" begin="42376" count="810" />
            <fluid mkfluid="0" mk="1" begin="43186" count="128310" />
        </particles>
        <constants>
            <data2d value="false" />
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.0085" units_comment="metres (m)" />
            <h value="0.014722431864" units_comment="metres (m)" />
            <b value="162005.14286" units_comment="Pascal (Pa)" />
            <massbound value="0.000614125" units_comment="kg" />
            <massfluid value="0.000614125" units_comment="kg" />
        </constants>
        <motion />
        <vtkout mkboundfirst="10" mkfluidfirst="1">
            <vtkfile name="CaseDambreak_Box_Dp.vtk" mk="10" mkbound="0" />
            <vtkfile name="CaseDambreak_Building_Dp.vtk" mk="11,20" mkbound="1,10" />
        </vtkout>
    </execution>
</case>
"""


#: feynman0406/DualSPHysicsGPT CaseDambreak_Def_test_out/CaseDambreak_Def.xml, GenCase v5.4.354.01
#: (07-04-2025): a tank drawn up to pointmax (1.6, 0.01, 0.4) at dp 0.01. Its log
#: (CaseDambreak_Def.out): "Case domain: (0,0,0)-(159,0,39)", "Domain points: 160 x 1 x 40 =
#: 6,400": no node on pointmax; the front face (y = 0) covers the one y layer, the fluid drawn
#: before it included, the back face (y = 0.01) lies outside. 6,400 fixed particles, B = 0.
CASEDAMBREAK_DEF_V54 = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase v5.4.354.01 (07-04-2025)" date="27-09-2025 00:45:52">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" comment="Gravitational acceleration" units_comment="m/s^2" />
            <rhop0 value="1000" comment="Reference density of the fluid" units_comment="kg/m^3" />
            <rhopgradient value="2" comment="Initial density gradient 1:Rhop0, 2:Water column, 3:Max. water height (default=2)" />
            <hswl value="0" auto="true" comment="Max still water level for speed of sound via coefsound" units_comment="m" />
            <gamma value="7" comment="Tait EOS exponent for water" />
            <speedsystem value="0" auto="true" comment="Max system speed (auto from dam-break propagation)" />
            <coefsound value="20" comment="Speedsound = coefsound * speedsystem" />
            <speedsound value="0" auto="true" comment="Auto speed of sound" />
            <coefh value="1.0" comment="h = coefh * sqrt(3*dp^2) in 3D" />
            <_hdp value="2" comment="Alternative: h = hdp * dp" />
            <cflnumber value="0.2" comment="CFL number" />
        </constantsdef>
        <!-- 2D-style: use very thin Y thickness = Dp -->
        <mkconfig boundcount="20" fluidcount="20" />
        <geometry>
            <definition dp="0.01" units_comment="m">
                <pointmin x="0.0" y="0.0" z="0.0" />
                <pointmax x="1.6" y="0.01" z="0.4" />
            </definition>
            <commands>
                <mainlist>
                    <!-- DBC boundary generation (faces), not mDBC -->
                    <setshapemode>dp | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <!-- Fluid column (left-bottom corner), size 0.4 x (Dp) x 0.3 m -->
                    <setmkfluid mk="0" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0.0" y="0.0" z="0.0" />
                        <size x="0.4" y="0.01" z="0.3" />
                    </drawbox>
                    <!-- Tank walls: bottom, left, right, front, back (top open) -->
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>bottom | left | right | front | back</boxfill>
                        <point x="0.0" y="0.0" z="0.0" />
                        <size x="1.6" y="0.01" z="0.4" />
                    </drawbox>
                    <shapeout file="Tank" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="SavePosDouble" value="0" comment="Save double-precision positions (0=off)" />
            <parameter key="StepAlgorithm" value="1" comment="1:Verlet, 2:Symplectic" />
            <parameter key="VerletSteps" value="40" comment="Euler warmup steps for Verlet" />
            <parameter key="Kernel" value="2" comment="1:Cubic Spline, 2:Wendland" />
            <parameter key="ViscoTreatment" value="1" comment="1:Artificial, 2:Laminar+SPS, 3:Laminar" />
            <parameter key="Visco" value="0.01" comment="Artificial viscosity coeff (typ. 0.01)" />
            <parameter key="ViscoBoundFactor" value="1" comment="Multiply viscosity on boundary" />
            <parameter key="DensityDT" value="2" comment="DDT 0:None, 1:Molteni, 2:Fourtakas, 3:Fourtakas(full)" />
            <parameter key="DensityDTvalue" value="0.1" comment="DDT coefficient" />
            <parameter key="Shifting" value="0" comment="0:Off, 1:Ignore bound, 2:Ignore fixed, 3:Full" />
            <parameter key="ShiftCoef" value="-2" comment="Shifting coefficient" />
            <parameter key="ShiftTFS" value="0" comment="Free-surface threshold (1.5 for 2D, 2.75 for 3D if enabled)" />
            <parameter key="RigidAlgorithm" value="1" comment="0:collision-free, 1:SPH, 2:DEM, 3:Chrono" />
            <parameter key="FtPause" value="0.0" comment="Floating warmup freeze time (s)" />
            <parameter key="CoefDtMin" value="0.05" comment="dtmin = coefdtmin*h/speedsound" />
            <parameter key="DtIni" value="0" comment="Use default h/speedsound" />
            <parameter key="DtMin" value="0" comment="Use default coefdtmin*h/speedsound" />
            <parameter key="DtFixed" value="0" comment="Fixed dt disabled" />
            <parameter key="DtFixedFile" value="NONE" comment="External dt schedule disabled" />
            <parameter key="DtAllParticles" value="0" comment="0:Fluid/Floating only for dt calc" />
            <parameter key="TimeMax" value="1.0" comment="Total simulation time (s)" />
            <parameter key="TimeOut" value="0.01" comment="Output interval (s)" />
            <parameter key="PartsOutMax" value="1" comment="**DEPRECATED** % of fluid allowed outside domain" />
            <parameter key="RhopOutMin" value="700" comment="Min valid density (kg/m^3)" />
            <parameter key="RhopOutMax" value="1300" comment="Max valid density (kg/m^3)" />
            <simulationdomain comment="Defines domain of simulation (default=Uses minimum and maximum position of the generated particles)">
                <posmin x="default" y="default" z="default" comment="e.g.: x=0.5, y=default-1, z=default-10%" />
                <posmax x="default" y="default" z="default + 50%" />
            </simulationdomain>
        </parameters>
        <particles np="6400" nb="6400" nbf="6400" mkboundfirst="21" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="0" y="0" z="0" />
                    <posmax x="1.59" y="0" z="0.39" />
                </positions>
                <fixed count="6400" id="0-6399" mkcount="1" mkvalues="21" />
            </_summary>
            <fixed mkbound="0" mk="21" begin="0" count="6400" />
        </particles>
        <constants>
            <data2d value="false" />
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.01" units_comment="metres (m)" />
            <h value="0.017320508076" units_comment="metres (m)" />
            <b value="0" units_comment="Pascal (Pa)" />
            <massbound value="0.001" units_comment="kg" />
            <massfluid value="0.001" units_comment="kg" />
        </constants>
        <uservars>
            <varnum name="VResId" value="0" />
        </uservars>
        <motion />
        <vtkout mkboundfirst="21" mkfluidfirst="1">
            <vtkfile name="CaseDambreak_Def_Tank_Dp.vtk" mk="21" mkbound="0" />
        </vtkout>
    </execution>
</case>
"""


#: feynman0406/DualSPHysicsGPT CaseSloshingHR_Def_from_xml_out_direct/CaseSloshingHR_Def_from_xml.xml,
#: GenCase v5.4.354.01 (07-04-2025): a 2D tank (boxfill all) with <layers vdp="0,1,2,3"> (5,688
#: moving particles: closed rings of 1410 + 8k) and, after <setboxlimitmode mode="full">, a fillbox
#: whose top at 0.093 m (46.5 dp) filled the row at 0.094 m (21,103 = 449 x 47 fluid particles,
#: depth 0.092 m, b 116,038.28571 Pa). Its SloshingMotionData.dat (a rotation table) is not kept:
#: the test writes one.
CASESLOSHINGHR_V54 = """<?xml version="1.0" ?>
<case app="GenCase v5.4.354.01 (07-04-2025)" date="27-09-2025 00:45:07">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" comment="Gravitational acceleration" units_comment="m/s^2" />
            <rhop0 value="1000" comment="Reference density of the fluid" units_comment="kg/m^3" />
            <rhopgradient value="2" comment="Initial density gradient 1:Rhop0, 2:Water column, 3:Max. water height (default=2)" />
            <hswl value="0" auto="true" comment="Maximum still water level to calculate speedofsound using coefsound" units_comment="metres (m)" />
            <gamma value="7" comment="Polytropic constant for water used in the state equation" />
            <speedsystem value="0" auto="true" comment="Maximum system speed (by default the dam-break propagation is used)" />
            <coefsound value="30" comment="Coefficient to multiply speedsystem" />
            <speedsound value="0" auto="true" comment="Speed of sound to use in the simulation (by default speedofsound=coefsound*speedsystem)" />
            <hdp value="2" comment="Alternative option to calculate the smoothing length (h=hdp*dp)" />
            <cflnumber value="0.2" comment="Coefficient to multiply dt" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <definition dp="0.002" units_comment="metres (m)">
                <pointmin x="-1" y="0" z="-1" />
                <pointmax x="1" y="0" z="1" />
            </definition>
            <commands>
                <list name="GeometryForNormals">
                    <setactive drawpoints="0" drawshapes="1" />
                    <setshapemode>actual | bound</setshapemode>
                    <setnormalinvert invert="true" />
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>all</boxfill>
                        <point x="-0.45" y="-0.1" z="0" />
                        <size x="0.9" y="0.2" z="0.51" />
                        <layers vdp="-0.5" />
                    </drawbox>
                    <shapeout file="hdp" />
                    <resetdraw />
                </list>
                <mainlist>
                    <runlist name="GeometryForNormals" />
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <drawbox>
                        <boxfill>all</boxfill>
                        <point x="-0.45" y="-0.1" z="0" />
                        <size x="0.9" y="0.2" z="0.51" />
                        <layers vdp="0,1,2,3" />
                    </drawbox>
                    <setboxlimitmode mode="full" />
                    <setmkfluid mk="0" />
                    <setactive drawpoints="1" drawshapes="0" />
                    <fillbox x="0" y="0" z="0.02">
                        <modefill>void</modefill>
                        <point x="-0.5" y="-0.1" z="0" />
                        <size x="1" y="0.2" z="0.093" />
                    </fillbox>
                </mainlist>
            </commands>
        </geometry>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" finish="100" />
                <mvrotfile id="1" duration="100" anglesunits="degrees">
                    <file name="SloshingMotionData.dat" />
                    <axisp1 x="0" y="-1" z="0" />
                    <axisp2 x="0" y="1" z="0" />
                </mvrotfile>
            </objreal>
        </motion>
        <normals active="true">
            <norgeometry comment="Define initial configuration of normals before applying other configurations">
                <geometryfile file="[CaseName]_hdp_Actual.vtk" comment="File with boundary geometry (VTK format)" />
                <distanceh v="2.0" comment="Maximum orthogonal distance (H*value) to compute normals data (default=2)" />
            </norgeometry>
        </normals>
    </casedef>
    <execution>
        <parameters>
            <parameter key="SavePosDouble" value="0" comment="Saves particle position using double precision (default=0)" />
            <parameter key="Boundary" value="2" comment="Boundary method 1:DBC, 2:mDBC (default=1)" />
            <parameter key="SlipMode" value="1" comment="Slip mode for mDBC 1:DBC vel=0, 2:No-slip, 3:Free Slip (default=1)" />
            <parameter key="StepAlgorithm" value="2" comment="Step Algorithm 1:Verlet, 2:Symplectic (default=1)" />
            <parameter key="VerletSteps" value="40" comment="Verlet only: Number of steps to apply Euler timestepping (default=40)" />
            <parameter key="Kernel" value="2" comment="Interaction Kernel 1:Cubic Spline, 2:Wendland (default=2)" />
            <parameter key="ViscoTreatment" value="1" comment="Viscosity formulation 1:Artificial, 2:Laminar+SPS, 3:Laminar (default=1)" />
            <parameter key="Visco" value="0.02" comment="Viscosity value. Typically 0.01 for Artificial and 1e-6 m^2/s (water kinematic viscosity) for Laminar" />
            <parameter key="ViscoBoundFactor" value="1" comment="Multiply viscosity value with boundary (default=1)" />
            <parameter key="DensityDT" value="3" comment="Density Diffusion Term 0:None, 1:Molteni, 2:Fourtakas, 3:Fourtakas(full) (default=0)" />
            <parameter key="DensityDTvalue" value="0.1" comment="DDT value (default=0.1)" />
            <parameter key="Shifting" value="0" comment="Shifting mode 0:None, 1:Ignore bound, 2:Ignore fixed, 3:Full (default=0)" />
            <parameter key="ShiftCoef" value="-2" comment="Coefficient for shifting computation (default=-2)" />
            <parameter key="ShiftTFS" value="0" comment="Threshold to detect free surface. Typically 1.5 for 2D and 2.75 for 3D (default=0)" />
            <parameter key="RigidAlgorithm" value="1" comment="Rigid Algorithm 0:collision-free, 1:SPH, 2:DEM, 3:Chrono (default=1)" />
            <parameter key="FtPause" value="0.0" comment="Time to freeze the floatings at simulation start (warmup) (default=0)" units_comment="seconds" />
            <parameter key="CoefDtMin" value="0.05" comment="Coefficient to calculate minimum time step dtmin=coefdtmin*h/speedsound (default=0.05)" />
            <parameter key="DtIni" value="0" comment="Initial time step. Use 0 to default use (default=h/speedsound)" units_comment="seconds" />
            <parameter key="DtMin" value="0" comment="Minimum time step. Use 0 to default use (default=coefdtmin*h/speedsound)" units_comment="seconds" />
            <parameter key="DtFixed" value="0" comment="Fixed Dt value. Use 0 to disable (default=disabled)" units_comment="seconds" />
            <parameter key="DtFixedFile" value="NONE" comment="Dt values are loaded from file. Use NONE to disable (default=disabled)" units_comment="milliseconds (ms)" />
            <parameter key="DtAllParticles" value="0" comment="Velocity of particles used to calculate DT. 1:All, 0:Only fluid/floating (default=0)" />
            <parameter key="TimeMax" value="8.35" comment="Time of simulation" units_comment="seconds" />
            <parameter key="TimeOut" value="0.01" comment="Time out data" units_comment="seconds" />
            <parameter key="RhopOutMin" value="700" comment="Minimum rhop valid (default=700)" units_comment="kg/m^3" />
            <parameter key="RhopOutMax" value="1300" comment="Maximum rhop valid (default=1300)" units_comment="kg/m^3" />
            <parameter key="WrnPartsOut" value="1" comment="Active warning according to number of out particles (default=1)" />
            <parameter key="MinFluidStop" value="0" comment="Minimum proportion of initial fluid particles to continue the simulation 0:Never stops, 0.1:Stops when fluid drops to 10%. (default=0)" />
            <simulationdomain comment="Defines domain of simulation (default=Uses minimum and maximum position of the generated particles)">
                <posmin x="default" y="default" z="default" comment="e.g.: x=0.5, y=default-1, z=default-10%" />
                <posmax x="default" y="default" z="default" />
            </simulationdomain>
        </parameters>
        <particles np="26791" nb="5688" nbf="0" mkboundfirst="10" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="-0.456" y="0" z="-0.006" />
                    <posmax x="0.456" y="0" z="0.516" />
                </positions>
                <moving count="5688" id="0-5687" mkcount="1" mkvalues="10" />
                <fluid count="21103" id="5688-26790" mkcount="1" mkvalues="1" />
            </_summary>
            <moving mkbound="0" mk="10" begin="0" count="5688" refmotion="0" />
            <fluid mkfluid="0" mk="1" begin="5688" count="21103" />
        </particles>
        <constants>
            <data2d value="true" />
            <data2dposy value="0" units_comment="metres (m)" />
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.002" units_comment="metres (m)" />
            <h value="0.004" units_comment="metres (m)" />
            <b value="116038.28571" units_comment="Pascal (Pa)" />
            <massbound value="0.004" units_comment="kg" />
            <massfluid value="0.004" units_comment="kg" />
        </constants>
        <uservars>
            <varnum name="VResId" value="0" />
        </uservars>
        <motion>
            <objreal ref="0">
                <begin mov="1" start="0" finish="100" />
                <mvrotfile id="1" duration="100" anglesunits="degrees">
                    <file name="SloshingMotionData.dat" />
                    <axisp1 x="0" y="-1" z="0" />
                    <axisp2 x="0" y="1" z="0" />
                </mvrotfile>
            </objreal>
        </motion>
        <vtkout mkboundfirst="10" mkfluidfirst="1">
            <vtkfile name="CaseSloshingHR_Def_from_xml_hdp_Actual.vtk" mk="10" mkbound="0" />
        </vtkout>
    </execution>
</case>
"""

#: DualSPHysics/DualSPHysics examples/others/RedrawGenCase/RedrawSimple.xml, GenCase4 v4.0.055
#: (10-11-2017): a floor of oblique lines with gaps between them (mkbound 1), the gaps closed by
#: <redrawnear targettp="void" bordertp="bound" bordermk="1"> (mkbound 2), then a fill
REDRAWSIMPLE = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.055 (10-11-2017)" date="10-11-2017 18:48:07">
    <casedef>
        <constantsdef>
            <lattice bound="1" fluid="1" />
            <gravity x="0" y="0" z="-9.81" />
            <cflnumber value="0.2" />
            <hswl value="0" auto="true" />
            <speedsystem value="0" auto="true" />
            <coefsound value="30" />
            <speedsound value="0" auto="true" />
            <coefh value="1.2" />
            <gamma value="7" />
            <rhop0 value="1000" />
        </constantsdef>
        <mkconfig boundcount="220" fluidcount="8">
            <mkorientfluid mk="0" orient="Xyz" />
        </mkconfig>
        <geometry>
            <definition dp="0.05" units_comment="metres (m)">
                <pointmin x="-1" y="0" z="-1" />
                <pointmax x="36.5" y="0" z="13" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>real | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <drawline>
                        <point x="0" y="0" z="2" />
                        <point x="0" y="0" z="0" />
                    </drawline>
                    <setmkbound mk="1" />
                    <drawline>
                        <point x="0" y="0" z="0" />
                        <point x="1" y="0" z="0" />
                    </drawline>
                    <drawline>
                        <point x="1.1" y="0" z="0" />
                        <point x="3" y="0" z="0.5" />
                    </drawline>
                    <drawline>
                        <point x="3.1" y="0" z="0.5" />
                        <point x="3.5" y="0" z="0.5" />
                    </drawline>
                    <drawline>
                        <point x="3.6" y="0" z="0.6" />
                        <point x="3.75" y="0" z="0.25" />
                    </drawline>
                    <drawlines>
                        <point x="3.75" y="0" z="0.25" />
                        <point x="4.5" y="0" z="0.25" />
                        <point x="6" y="0" z="2" />
                    </drawlines>
                    <cellsout file="test_00" />
                    <setmkbound mk="2" />
                    <redrawnear times="1" targettp="void" bordertp="bound" bordermk="1" />
                    <cellsout file="test_01" />
                    <setmkfluid mk="0" />
                    <fillbox x="0.5" y="0" z="0.5">
                        <modefill>void</modefill>
                        <point x="0" y="-1" z="0" />
                        <size x="6" y="2" z="1.5" />
                    </fillbox>
                    <cellsout file="test_02" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.01" />
            <parameter key="ViscoBoundFactor" value="0" />
            <parameter key="FtPause" value="1.0" />
            <parameter key="TimeMax" value="1" />
            <parameter key="TimeOut" value="0.01" />
        </parameters>
        <particles np="2816" nb="552" nbf="552" mkboundfirst="9" mkfluidfirst="1">
            <_summary>
                <fixed count="552" id="0-551" mkcount="3" mkvalues="9-11" />
                <fluid count="2264" id="552-2815" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="9" begin="0" count="40" />
            <fixed mkbound="1" mk="10" begin="40" count="157" />
            <fixed mkbound="2" mk="11" begin="197" count="355" />
            <fluid mkfluid="0" mk="1" begin="552" count="2264" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.05" units_comment="metres (m)" />
            <h value="8.4852813742E-002" units_comment="metres (m)" />
            <b value="1.7027357143E+006" units_comment="Pascal (Pa)" />
            <massbound value="2.5000000000E+000" units_comment="kg" />
            <massfluid value="2.5000000000E+000" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""

#: DualSPHysics/DualSPHysics examples/others/RedrawGenCase/RedrawComplex.xml, GenCase4 v4.0.055
#: (10-11-2017): the word HELLO! in fluid mk 0-5 over a lattice filled with mkbound 0 by
#: <redraw/>, then <redraw mkfluid>, <redrawbox>, <redrawnear times> growing each letter, and
#: <setmkvoid/> with <redrawnear> and <redrawnearbox bordertp="void"> cutting the outlines free
REDRAWCOMPLEX = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase4 v4.0.055 (10-11-2017)" date="10-11-2017 17:54:37">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <cflnumber value="0.2" />
            <hswl value="0" auto="true" />
            <speedsystem value="0" auto="true" />
            <coefsound value="30" />
            <speedsound value="0" auto="true" />
            <coefh value="1.0" />
            <gamma value="7" />
            <rhop0 value="1000" />
        </constantsdef>
        <mkconfig boundcount="220" fluidcount="8">
            <mkorientfluid mk="0" orient="Xyz" />
        </mkconfig>
        <geometry>
            <definition dp="0.1" units_comment="metres (m)">
                <pointmin x="0" y="0" z="0" />
                <pointmax x="36.5" y="0" z="13" />
            </definition>
            <commands>
                <list name="CharH" printcall="true">
                    <drawline>
                        <point x="0" y="0" z="0" />
                        <point x="0" y="0" z="8" />
                    </drawline>
                    <drawline>
                        <point x="4" y="0" z="0" />
                        <point x="4" y="0" z="8" />
                    </drawline>
                    <drawline>
                        <point x="-0.2" y="0" z="4" />
                        <point x="4.2" y="0" z="4" />
                    </drawline>
                </list>
                <list name="CharE" printcall="true">
                    <drawline>
                        <point x="0" y="0" z="0" />
                        <point x="0" y="0" z="8" />
                    </drawline>
                    <drawline>
                        <point x="-0.2" y="0" z="0" />
                        <point x="4.2" y="0" z="0" />
                    </drawline>
                    <drawline>
                        <point x="-0.2" y="0" z="4" />
                        <point x="3.5" y="0" z="4" />
                    </drawline>
                    <drawline>
                        <point x="-0.2" y="0" z="8" />
                        <point x="4.2" y="0" z="8" />
                    </drawline>
                </list>
                <list name="CharL" printcall="true">
                    <drawline>
                        <point x="0" y="0" z="0" />
                        <point x="0" y="0" z="8" />
                    </drawline>
                    <drawline>
                        <point x="-0.2" y="0" z="0" />
                        <point x="4.2" y="0" z="0" />
                    </drawline>
                </list>
                <list name="CharO" printcall="true">
                    <drawlines>
                        <point x="0.5" y="0" z="0" />
                        <point x="3.5" y="0" z="0" />
                        <point x="4.0" y="0" z="0.5" />
                        <point x="4.0" y="0" z="7.5" />
                        <point x="3.5" y="0" z="8" />
                        <point x="0.5" y="0" z="8" />
                        <point x="0.0" y="0" z="7.5" />
                        <point x="0.0" y="0" z="0.5" />
                        <point x="0.5" y="0" z="0.0" />
                    </drawlines>
                </list>
                <list name="CharSim" printcall="true">
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="0.4" y="-1" z="2.6" />
                        <size x="0.8" y="2" z="4.5" />
                    </drawbox>
                    <drawcylinder radius="0.5" mask="0">
                        <point x="0.8" y="-1" z="1.1" />
                        <point x="0.8" y="1" z="1.1" />
                    </drawcylinder>
                </list>
                <mainlist>
                    <setshapemode>real | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <redraw />
                    <cellsout file="test_00" />
                    <move x="2.5" y="0" z="2" />
                    <setmkfluid mk="0" />
                    <runlist name="CharH" />
                    <cellsout file="test_01" />
                    <move x="6.7" y="0" z="0" />
                    <setmkfluid mk="1" />
                    <runlist name="CharE" />
                    <cellsout file="test_02" />
                    <move x="6.3" y="0" z="0" />
                    <setmkfluid mk="2" />
                    <runlist name="CharL" />
                    <cellsout file="test_03" />
                    <move x="6.0" y="0" z="0" />
                    <setmkfluid mk="3" />
                    <runlist name="CharL" />
                    <cellsout file="test_04" />
                    <move x="6.0" y="0" z="0" />
                    <setmkfluid mk="4" />
                    <runlist name="CharO" />
                    <cellsout file="test_05" />
                    <move x="6.0" y="0" z="0" />
                    <setmkfluid mk="5" />
                    <runlist name="CharSim" />
                    <cellsout file="test_06" />
                    <redraw mkfluid="0" />
                    <cellsout file="test_07" />
                    <matrixreset />
                    <setmkfluid mk="0" />
                    <redrawbox mkfluid="5">
                        <point x="32" y="-1" z="0" />
                        <size x="4" y="2" z="10" />
                    </redrawbox>
                    <cellsout file="test_08" />
                    <setmkfluid mk="5" />
                    <redrawnear times="7" targettp="bound" targetmk="0" bordertp="fluid" bordermk="5" />
                    <cellsout file="test_09" />
                    <setmkfluid mk="1" />
                    <redrawnear times="5" targettp="bound" targetmk="0" bordertp="fluid" bordermk="1" />
                    <cellsout file="test_10" />
                    <setmkfluid mk="2" />
                    <redrawnear times="3" targettp="bound" targetmk="0" bordertp="fluid" bordermk="2" />
                    <cellsout file="test_11" />
                    <setmkfluid mk="3" />
                    <redrawnear times="1" targettp="bound" targetmk="0" bordertp="fluid" bordermk="3" />
                    <cellsout file="test_12" />
                    <setmkvoid />
                    <redrawnear times="1" targettp="bound" targetmk="0" bordertp="fluid" />
                    <cellsout file="test_13" />
                    <redrawnearbox times="2" targettp="bound" targetmk="0" bordertp="void">
                        <point x="0" y="-1" z="0" />
                        <size x="42" y="2" z="13" />
                    </redrawnearbox>
                    <cellsout file="test_14" />
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="PosDouble" value="1" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.01" />
            <parameter key="ViscoBoundFactor" value="0" />
            <parameter key="DensityDT" value="1" />
            <parameter key="FtPause" value="1.0" />
            <parameter key="TimeMax" value="3" />
            <parameter key="TimeOut" value="0.01" />
        </parameters>
        <particles np="40958" nb="33268" nbf="33268" mkboundfirst="9" mkfluidfirst="1">
            <_summary>
                <fixed count="33268" id="0-33267" mkcount="1" mkvalues="9" />
                <fluid count="7690" id="33268-40957" mkcount="6" mkvalues="1-6" />
            </_summary>
            <fixed mkbound="0" mk="9" begin="0" count="33268" />
            <fluid mkfluid="0" mk="1" begin="33268" count="511" />
            <fluid mkfluid="1" mk="2" begin="33779" count="2376" />
            <fluid mkfluid="2" mk="3" begin="36155" count="917" />
            <fluid mkfluid="3" mk="4" begin="37072" count="381" />
            <fluid mkfluid="4" mk="5" begin="37453" count="220" />
            <fluid mkfluid="5" mk="6" begin="37673" count="3285" />
        </particles>
        <constants>
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="1000" units_comment="kg/m^3" />
            <dp value="0.1" units_comment="metres (m)" />
            <h value="1.4142135624E-001" units_comment="metres (m)" />
            <b value="1.1856085714E+007" units_comment="Pascal (Pa)" />
            <massbound value="1.0000000000E+001" units_comment="kg" />
            <massfluid value="1.0000000000E+001" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""


#: MYF940103/GeoDualSPHysics_v5.2_private examples/Hydromechanic coupling/01_SelfWeightConsolidation_PR/
#: support/diagnostics/diag2_hydrostatic_constantz_fixeddt_t02/CaseHydrostaticSteady.xml, GenCase
#: v5.0.278c (30-10-2023): a soil column in a U drawn by <drawbeach>, the lattice cleared by
#: <setmkvoid/><redraw/>, the walls thickened by a full-mode <fillbox> and <redrawnear times="3">,
#: the rest of that fill erased by <redraw mkbound="1"> under the void pen, the side walls then
#: erased by void fills: 40 floor particles and 1000 fluid. The fork's <soils> section and its own
#: parameters (DPCtes, ArtificialStress, SoilDamping...) are left out; the geometry is the file's.
HYDROSTATICSTEADY_GEO = """<?xml version="1.0" encoding="UTF-8" ?>
<case app="GenCase v5.0.278c (30-10-2023)" date="04-06-2026 02:29:43">
    <casedef>
        <constantsdef>
            <gravity x="0" y="0" z="-9.81" />
            <rhop0 value="2100" />
            <hswl value="0" auto="true" />
            <gamma value="7" />
            <speedsystem value="0" auto="true" />
            <coefsound value="20" />
            <speedsound value="0" auto="true" />
            <hdp value="1.8" />
            <cflnumber value="0.2" />
        </constantsdef>
        <mkconfig boundcount="240" fluidcount="9" />
        <geometry>
            <predefinition>
                <newvarcte sizefx="0.1" _rem="Soil column width" />
                <newvarcte sizefz="1.0" _rem="Soil column height" />
                <newvarcte sizebx="0.1" _rem="Boundary width" />
                <newvarcte sizebz="1.2" _rem="Boundary height" />
                <newvarcte Dp="0.01" _rem="Particle spacing" />
            </predefinition>
            <definition dp="#Dp" units_comment="metres (m)">
                <pointmin x="#-sizefz/2+Dp/2" y="0" z="#-sizefz/2+Dp/2" />
                <pointmax x="#sizefz*1.5+Dp/2" y="0" z="#sizebz*1.5+Dp/2" />
            </definition>
            <commands>
                <mainlist>
                    <setshapemode>actual | bound</setshapemode>
                    <setnormalinvert invert="false" />
                    <move x="0" y="-0.1" z="0" />
                    <setmkbound mk="0" />
                    <drawbeach mask="1|2|6">
                        <point x="0" y="0.2" z="#sizebz" />
                        <point x="0" y="0.2" z="0" />
                        <point x="#sizebx" y="0.2" z="0" />
                        <point x="#sizebx" y="0.2" z="#sizebz" />
                    </drawbeach>
                    <matrixreset />
                    <shapeout file="hdp" />
                    <setmkvoid />
                    <redraw />
                    <setshapemode>actual | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <setnormalinvert invert="true" />
                    <move x="0" y="-0.1" z="0" />
                    <drawbeach mask="1|2|6">
                        <point x="#-Dp/2" y="0.2" z="#sizebz+Dp/2" />
                        <point x="#-Dp/2" y="0.2" z="#-Dp/2" />
                        <point x="#sizebx+Dp/2" y="0.2" z="#-Dp/2" />
                        <point x="#sizebx+Dp/2" y="0.2" z="#sizebz+Dp/2" />
                    </drawbeach>
                    <shapeout file="Boundary" />
                    <matrixreset />
                    <setmkbound mk="1" />
                    <setboxlimitmode mode="full" />
                    <fillbox x="#-1.5*Dp" y="0" z="#-1.5*Dp">
                        <modefill>void</modefill>
                        <point x="#-Dp*10" y="-1" z="#-Dp*10" />
                        <size x="#(sizebx+Dp*20)" y="2" z="#(sizebz+Dp*10)" />
                    </fillbox>
                    <setboxlimitmode mode="full" />
                    <setmkbound mk="0" />
                    <redrawnear times="3" targettp="bound" targetmk="1" bordertp="bound" bordermk="0" />
                    <setmkvoid />
                    <redraw mkbound="1" />
                    <setmkfluid mk="0" />
                    <fillbox x="#Dp/2" y="0" z="#Dp/2">
                        <modefill>void</modefill>
                        <point x="#-Dp/2" y="-1" z="#-Dp/2" />
                        <size x="#(sizefx)" y="2" z="#(sizefz)" />
                    </fillbox>
                    <setmkvoid />
                    <fillbox x="#-Dp/2" y="0" z="#Dp/2">
                        <modefill>bound</modefill>
                        <point x="#-Dp*10.5" y="-1" z="#-Dp*10.5" />
                        <size x="#Dp*10" y="2" z="#(sizebz+Dp*10.5)" />
                    </fillbox>
                    <setmkvoid />
                    <fillbox x="#sizebx+Dp" y="0" z="#Dp">
                        <modefill>bound</modefill>
                        <point x="#sizefx+Dp/2" y="-1" z="#-Dp*10" />
                        <size x="#(Dp*10)" y="2" z="#(sizebz+Dp*10)" />
                    </fillbox>
                </mainlist>
            </commands>
        </geometry>
    </casedef>
    <execution>
        <parameters>
            <parameter key="Boundary" value="2" />
            <parameter key="StepAlgorithm" value="2" />
            <parameter key="Visco" value="0.4" />
            <parameter key="CoefDtMin" value="0.001" />
            <parameter key="DtIni" value="0.000001" />
            <parameter key="DtMin" value="0.00000001" />
            <parameter key="DtFixed" value="0.000001" />
            <parameter key="TimeMax" value="0.2" />
            <parameter key="TimeOut" value="0.02" />
            <parameter key="RhopOutMax" value="3000" />
        </parameters>
        <particles np="1040" nb="40" nbf="40" mkboundfirst="10" mkfluidfirst="1">
            <_summary>
                <positions units_comment="metres (m)">
                    <posmin x="0.005" y="0" z="-0.035" />
                    <posmax x="0.095" y="0" z="0.995" />
                </positions>
                <fixed count="40" id="0-39" mkcount="1" mkvalues="10" />
                <fluid count="1000" id="40-1039" mkcount="1" mkvalues="1" />
            </_summary>
            <fixed mkbound="0" mk="10" begin="0" count="40" />
            <fluid mkfluid="0" mk="1" begin="40" count="1000" />
        </particles>
        <constants>
            <data2d value="true" />
            <data2dposy value="0" units_comment="metres (m)" />
            <gravity x="0" y="0" z="-9.81" units_comment="m/s^2" />
            <cflnumber value="0.2" />
            <gamma value="7" />
            <rhop0 value="2100" units_comment="kg/m^3" />
            <dp value="0.01" units_comment="metres (m)" />
            <h value="0.018" units_comment="metres (m)" />
            <b value="1165428" units_comment="Pascal (Pa)" />
            <massbound value="0.21" units_comment="kg" />
            <massfluid value="0.21" units_comment="kg" />
        </constants>
        <motion />
    </execution>
</case>
"""
