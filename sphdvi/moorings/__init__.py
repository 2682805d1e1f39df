"""Mooring lines: DualSPHysics's MoorDynPlus lumped-mass model (sphdvi.moorings.lines), its coupling to
the floating bodies (sphdvi.moorings.system) and the quasi-static elastic catenary (sphdvi.moorings.catenary)."""
