"""Indices into the packed float64 constant vector passed to the kernels."""
H = 0          # smoothing length h
R2MAX = 1      # (2h)^2
ETA2 = 2       # (0.1 h)^2
ALPHA = 3      # kernel normalisation alpha_D
ALPHA_H2 = 4   # alpha_D / h^2
CS0 = 5        # speed of sound c0
VISCO = 6      # Visco (alpha of artificial viscosity, or nu for laminar)
VISCO_BOUND = 7  # Visco * ViscoBoundFactor
DDT_COEF = 8   # DensityDTvalue * 2h * c0
DDT_GZ = 9     # rhop0 * gz / B  (hydrostatic correction of Fourtakas)
RHOP0 = 10     # reference density
INV_GAMMA = 11  # 1/gamma
GX = 12
GY = 13
GZ = 14
OD_WDELTAP = 15  # 1/W(dp): tensile correction of the cubic spline
B = 16         # Tait constant B = c0^2 rhop0 / gamma
GAMMA = 17
STENCIL = 18   # cells searched on each side: 1 (cell size 2h) or 2 (cell size h)
NCONST = 19
