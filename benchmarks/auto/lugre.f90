!---------------------------------------------------------------------------------------------
! AUTO-07p equations of the chapter-8 LuGre loop (Table 8.1) for benchmarks/bench_auto.py.
! |x2| is smoothed as sqrt(x2^2 + eps^2) (eps = 10**PAR(2), so continuation in eps is in decades), as AUTO needs a smooth vector field.
! PAR(1) = K, PAR(11) = period. U(4) = sigma0 z (the bristle force, N m) keeps the unknowns of
! comparable size for AUTO's Newton iteration.
!---------------------------------------------------------------------------------------------
SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC
  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)
  DOUBLE PRECISION, PARAMETER :: PI = 3.14159265358979323846D0
  DOUBLE PRECISION, PARAMETER :: J = 0.026D0, CM = 16.D0, FS = 0.53D0, FC = 0.44D0, VS = 0.02D0
  DOUBLE PRECISION, PARAMETER :: S0 = 2.2D4, S1 = 7.58D0, S2 = 0.1D0
  DOUBLE PRECISION K, EPS, V, AV, G, ZD, FF, UC
  K = PAR(1)
  EPS = 10.D0**PAR(2)
  V = U(2)
  AV = SQRT(V * V + EPS * EPS)
  G = FC + (FS - FC) * EXP(-(V / VS)**2)
  ZD = V - AV * U(4) / G
  FF = U(4) + S1 * ZD + S2 * V
  UC = -K * (2.D0 * U(1) + V / (2.D0 * PI) + 2.D0 * PI * U(3))
  F(1) = V
  F(2) = (CM * UC - FF) / J
  F(3) = U(1)
  F(4) = S0 * ZD
END SUBROUTINE FUNC

SUBROUTINE STPNT(NDIM,U,PAR,T)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM
  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(IN) :: T
  PAR(1) = 0.3D0
  PAR(2) = -9.D0
END SUBROUTINE STPNT

SUBROUTINE BCND
END SUBROUTINE BCND

SUBROUTINE ICND
END SUBROUTINE ICND

SUBROUTINE FOPT
END SUBROUTINE FOPT

SUBROUTINE PVLS
END SUBROUTINE PVLS
