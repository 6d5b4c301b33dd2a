"""Butcher tableaux, dense-output coefficients and Radau IIA constants.

Taken from scipy's integrators (the same published coefficients: Dormand & Prince 1980 for
RK45, Hairer's DOP853, Hairer & Wanner's RADAU5) so that both sides of a benchmark use
identical methods. Module-level arrays are frozen into the numba kernels as constants.
"""
import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _d853
from scipy.integrate._ivp import radau as _radau
from scipy.integrate._ivp.rk import RK45 as _RK45

# Dormand-Prince 5(4), 7 stages with FSAL, 4th-order dense output.
DP5_C = np.ascontiguousarray(_RK45.C, dtype=np.float64)          # (6,)
DP5_A = np.ascontiguousarray(_RK45.A, dtype=np.float64)          # (6, 5)
DP5_B = np.ascontiguousarray(_RK45.B, dtype=np.float64)          # (6,)
DP5_E = np.ascontiguousarray(_RK45.E, dtype=np.float64)          # (7,)
DP5_P = np.ascontiguousarray(_RK45.P, dtype=np.float64)          # (7, 4)

# Dormand-Prince 8(5,3), 12 stages + FSAL, 3 extra stages for 7th-order dense output.
D853_NS = int(_d853.N_STAGES)                                    # 12
D853_NSE = int(_d853.N_STAGES_EXTENDED)                          # 16
D853_A = np.ascontiguousarray(_d853.A, dtype=np.float64)         # (16, 16)
D853_B = np.ascontiguousarray(_d853.B, dtype=np.float64)         # (12,)
D853_C = np.ascontiguousarray(_d853.C, dtype=np.float64)         # (16,)
D853_E3 = np.ascontiguousarray(_d853.E3, dtype=np.float64)       # (13,)
D853_E5 = np.ascontiguousarray(_d853.E5, dtype=np.float64)       # (13,)
D853_D = np.ascontiguousarray(_d853.D, dtype=np.float64)         # (4, 16)

# Radau IIA, 3 stages, order 5 (collocation at c, c[2] = 1).
_S6 = 6.0 ** 0.5
RADAU_C = np.ascontiguousarray(_radau.C, dtype=np.float64)       # (3,)
RADAU_A = np.array([
    [(88 - 7 * _S6) / 360, (296 - 169 * _S6) / 1800, (-2 + 3 * _S6) / 225],
    [(296 + 169 * _S6) / 1800, (88 + 7 * _S6) / 360, (-2 - 3 * _S6) / 225],
    [(16 - _S6) / 36, (16 + _S6) / 36, 1.0 / 9.0],
])
RADAU_E = np.ascontiguousarray(_radau.E, dtype=np.float64)       # (3,) error estimate weights
RADAU_P = np.ascontiguousarray(_radau.P, dtype=np.float64)       # (3, 3) dense output
RADAU_MU_REAL = float(_radau.MU_REAL)

# Method identifiers shared by the kernels and the front end.
METHOD_DP5 = 0
METHOD_DOP853 = 1
METHOD_RADAU = 2
METHODS = {"dp5": METHOD_DP5, "rk45": METHOD_DP5, "dop853": METHOD_DOP853, "radau": METHOD_RADAU}
METHOD_ORDER = {METHOD_DP5: 5, METHOD_DOP853: 8, METHOD_RADAU: 5}
# Exponent of the error norm in the step-size controller: -1 / (error estimator order + 1).
ERROR_EXPONENT = {METHOD_DP5: -1.0 / 5.0, METHOD_DOP853: -1.0 / 8.0, METHOD_RADAU: -1.0 / 4.0}
