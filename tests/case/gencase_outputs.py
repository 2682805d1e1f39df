"""GenCase's own output files (a case file GenCase wrote, with its record of what it drew), as test inputs."""

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
