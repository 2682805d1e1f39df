"""GenCase drawing: the ``<geometry>`` section of a case turned into particles.

Entry point: :func:`run_geometry` (returns a :class:`Drawing`).

Lattice
    Nodes at ``origin + k*dp``; ``origin`` = ``pointmin``, or with
    ``<pointref>`` the first node >= ``pointmin`` of the lattice through
    ``pointref`` (not along y in 2D). Each axis holds
    ``floor((pointmax - pointmin)/dp)`` nodes, none on ``pointmax`` (GenCase's
    "Domain points"); in 2D (``pointmin.y == pointmax.y``) every node has
    ``y = pointmin.y``. The lattice is a dense ``uint16`` canvas (at most
    ``max_nodes`` nodes); a later drawing overwrites earlier ones, void erases.

Pen
    ``setmkfluid``/``setmkbound``/``setmkvoid`` choose what is written (drawing
    before any of them is an error); ``setmknextbound``/``setmknextfluid``
    (``next="true"``) take the last mk of that kind plus one. Transforms (``move``, ``rotate``,
    ``rotateline``, ``scale``) multiply the current matrix on the right
    (OpenGL order); ``matrixsave/load`` and ``statesave/load`` are stacks.

Draw modes (``setdrawmode``)
    ``full`` = volume including its surface, ``solid`` = volume (nodes inside,
    boundary within 1e-6 dp included), ``face`` = surface only, ``wire`` =
    edges (polyhedra; curved shapes draw their surface). A closed sphere,
    ellipsoid or cylinder in ``full`` mode fills the nodes within r + 0.6 dp
    (GenCase's records, ``shapes.CURVED_FULL_REACH``).
    ``drawbox`` with ``<boxfill>`` ignores the mode: ``solid`` = volume,
    ``all`` or any of ``bottom|top|left|right|front|back`` = those faces
    (left/right = x min/max, front/back = y min/max, bottom/top = z min/max),
    ``|`` adds and ``^`` removes (``all ^ top``), left to right.
    Planar shapes (triangle, quadri, strips, fans, polygon, triangles) are
    surfaces in every mode but ``wire``. Mesh files draw their surface, plus
    the inside (even-odd rule) with ``autofill="true"``.

Boxes (GenCase's rule, checked against the particle counts GenCase wrote for
three DualSPHysics example cases, on and off the lattice)
    Volume: every node from the one nearest the min corner to the one
    nearest the max corner, i.e. the box widened by dp/2; a corner half-way
    between two nodes goes where its double-precision lattice coordinate
    (x - origin)/dp rounds, with no tolerance, as GenCase v5.4's do.
    Face: the node layer nearest the face plane, over the same extent; a
    ``<layers>`` copy lies a whole number of nodes from the first. For a
    rotated box the volume is the box widened by dp/2 along its own axes and
    the faces follow the planar-surface rule below (GenCase draws rotated
    faces somewhat thicker: 960 vs 832 nodes in its RotatedBox example).

Surfaces (see :mod:`.raster`)
    Planar faces: nodes whose distance to the plane is in (-dp/2, dp/2] and
    whose projection lies within dp/2 of the face (for an axis-aligned box face:
    the node layer nearest the plane over the face's extent rounded to the
    nearest nodes). Curved surfaces: the inner shell (inside nodes with an
    outside face-neighbour). Both are closed against face-connected leaks.

Masks (``drawprism``, ``drawbeach``, ``drawpyramid``, ``drawcylinder``)
    ``mask`` lists the numbers (from 1) of the faces left out, joined by ``|``
    (``mask="1 | 2 | 6 | 7"`` leaves out faces 1, 2, 6 and 7; ``0`` none;
    numbers beyond the shape's faces hide nothing; a mask naming no face of the shape at all is
    warned about, one beside valid faces passes silently like GenCase's). Prism (first polygon, then
    second polygon): 1 = first polygon, 2 = second polygon, 3, 4, ... = sides
    (side k joins points k-2 and k-1 of each polygon, the last one closes it).
    Pyramid (apex, then base points): 1 = base, 2, 3, ... = sides apex-P1P2,
    apex-P2P3, ... Cylinder: 1 = cover at the first point, 2 = cover at the
    second point, 3 = tube. A shape with a face left out is open: ``full``
    draws its remaining faces only (no inside), ``wire`` the edges of the
    remaining faces, ``solid`` (no surface) the closed shape's volume as
    without the mask. The recorded shape (``shapeout``, ``norgeometry``) holds
    the remaining faces.
    Evidence: the DualSPHysics v5.4 examples CaseWavemaker, CasePointAbsorber
    and CaseFloatingWavesVal only make sense with faces listed (as bits their
    masks would draw a lid, a diagonal through the water or a wall over the
    piston), and their fillbox seeds (or the fluid drawn before) lie inside
    the masked prism drawn in full mode, so GenCase leaves it hollow; GenCase
    v4.0.053's record of motion/Motion08 has three short cylinders with
    mask="1" drawn in solid mode as whole disks (110, 311, 312 particles). The
    cylinder and pyramid numbering is inferred (caps first, like prisms).

Beach (``drawbeach``, 2D cases only)
    The closed x-z polygon of the profile points extruded along y across the
    2D plane; faces and ``mask`` as a prism's (1, 2 the profile polygons, 3...
    the sides, the last closing the profile). 3D cases are refused (the y
    extent is not documented).

Extrusion (``drawextrude closed="false"``)
    The open polyline of the points swept by ``<extrude>``: a surface (the
    planar-surface rule) in every mode but ``wire`` (its quadrilaterals'
    edges). ``<layers>`` moves it offset*dp along the face normals
    (P_i+1 - P_i) x extrude (a mitred parallel curve). ``closed="true"`` is
    refused.

Ellipsoid
    ``<point>`` (or ``<center>``) + ``<radius x y z>`` (or ``<size>``):
    semi-axes along x, y, z; or the GenCase template form ``radius`` + two
    ``<point>``: the ellipsoid of revolution with those foci and semi-major
    axis ``radius`` (|p-f1| + |p-f2| <= 2 radius).

Fills (``fillpoint``, ``fillvoidpoint``, ``fillbox``)
    From the node nearest the seed, a 6-connected (4 in 2D) flood through
    nodes whose kind is listed in ``<modefill>`` (void, fluid, bound; the
    ``mkfluid``/``mkbound`` attributes restrict fluid/bound nodes to that mk;
    ``border`` alone means void, GenCase users see no difference), limited to
    the lattice or to the ``fillbox`` box (the nodes at least dp/2 inside it, as GenCase fills:
    one layer less than a solid box where a face lies on the lattice; under a rotation the box's
    own axes are used, sphdvi's extension of that rule: GenCase's outputs show no turned fill box). Every reached node
    gets the current pen. A seed outside, or on a node of another kind, fills
    nothing (warning).

``shapeout``
    Writes the shapes drawn since the last reset as triangles into
    ``outdir/<casename>_<base name>.<format>`` (vtk, vtp, vtu, stl; ``file=""``
    gives ``<casename>_Shapes``); the file attribute is reduced to its base
    name, so nothing is ever written outside outdir. Nothing is written when
    outdir is None.

Layers (``<layers vdp="0,1,-0.5*">`` in drawbox, drawsphere, drawcylinder)
    The shape is drawn once per offset, widened by offset*dp on every side
    (solid box), on the radius (sphere), on the radius and at both covers
    (cylinder); negative offsets shrink it. A box's face is moved offset*dp
    along its normal and widened towards its drawn neighbouring faces only
    (the layers of an open tank close its corners, its walls do not rise).
    A trailing ``*`` is ignored; an empty ``vdp`` draws the shape once.

``resetdraw``
    Back to the initial drawing configuration: no mk selected, ``full`` mode,
    identity matrix, points and shapes active (``setactive``), no line start. Variables, lists, saved stacks (``matrixsave``,
    ``statesave``, ``mksave``) and the particles drawn so far are kept
    (GenCase_CaseTemplate.xml lists it as a plain state command).

Commands that draw nothing
    A fluid or boundary drawing command none of whose nodes lies in the
    domain (a 2D shape that misses the plane y = posy, a shape outside
    pointmin..pointmax) is warned about with its line and mk; fills and void
    drawing are not (they may rightly change nothing).

``setboxlimitmode``
    ``inner`` (the default) limits a ``<fillbox>`` to the nodes at least dp/2 inside its box,
    ``full`` to the nodes of a solid ``<drawbox>`` over it.

Lines (``drawline``, ``drawlines``, ``drawlineto``; the edges in ``wire`` mode)
    The nodes within 0.6 dp of the segment: one node a step along an axis or a 45-degree
    diagonal, a second one where an oblique line passes near the middle of two (GenCase v4.0's
    records of DualSPHysics's examples RedrawSimple and RedrawComplex).

Redraw (``redraw``, ``redrawbox``, ``redrawnear``, ``redrawnearbox``; see :mod:`.redraw`)
    They give the current pen (void erases) to nodes chosen by what they hold. ``redraw`` takes
    every node holding ``mkfluid``/``mkbound`` (every node, void included, without either);
    ``redrawbox`` the same within a box (the nodes of a solid ``<drawbox>``, under a rotation too).
    ``redrawnear times targettp targetmk bordertp bordermk`` takes, ``times`` passes over, the
    target nodes (void, fluid or bound, joined by ``|``; of mk ``targetmk`` if given) with a
    border node among their 26 neighbours (8 in 2D); a pen equal to the border grows it a layer
    a pass. ``redrawnearbox`` limits the targets to a box. ``<dirfilter>`` other than ``all``
    is refused (its direction rule is not documented). A redraw that changes no node is warned
    about. GenCase v4.0's records of RedrawSimple and RedrawComplex are matched count for count.

Bathymetries (``drawbathymetry``, ``drawfilecsv mode="bathymetry"``; see :mod:`.bathymetry`)
    A bed z(x, y) drawn as a triangulated surface by the planar-surface rule (fill the void under
    it to make it solid). ``<zpoints file>`` (XYZ text or VTK points; ``<scale>``, ``<rotate x y
    z>``, ``<move>`` in that order, then ``<selection>`` in x, y) is triangulated (Delaunay in
    x, y) and drawn as it is, or with ``<grid dp>`` resampled on a grid of spacing dp over
    ``<initdomain>`` (else the points' extent) by linear interpolation on the triangulation, the
    nearest point's height outside it (warned); ``<expands>`` adds ramps at the sides (``size``
    to height ``z``, then ``size2`` to ``z2``; a missing height keeps the edge's),
    ``<finalmove>`` moves the bed. ``<grid file>`` gives the grid's points. ``<savepoints>``,
    ``<savegrid>`` write ``<casename>_Bathymetry_Points.vtk`` and ``..._Grid.vtk``. A CSV table
    (a label and the x values, then rows of y and heights) draws two triangles a cell.
    ``<periodicx>``/``<periodicy>`` and sizes <= 0 are refused (not documented).

Not supported (CaseError "not supported by sphdvi"): see ``UNSUPPORTED``
(waves, clipping, patterns, ...)
and ``<layers>`` of ellipsoids; commands that only tune GenCase's own output or sampling
(``setdpctes``, ``setshapemode``, ``debugout``, ...) are accepted with no effect.
"""
from .commands import UNSUPPORTED, Drawing, run_geometry

__all__ = ["Drawing", "run_geometry", "UNSUPPORTED"]
