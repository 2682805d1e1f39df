"""Mooring lines: DualSPHysics's MoorDynPlus lumped-mass model (sphdvi.moorings.lines) and the quasi-static elastic catenary (sphdvi.moorings.catenary)."""
