!---------------------------------------------------------------------------
! AUTO-07p equations file: the Kirchhoff rod BVP of "Stable elastic knots
! with no self-contact", eq. (A.2), in the paper's scalings (L = 1, B11 = 1,
! B22 = K2, B33 = K3, no body force), with the clamps (2.9)-(2.13).
!
! State (NDIM = 18), s in [0, 1]:
!   U(1:3)   r        centreline (lab frame)
!   U(4:6)   d1       directors (lab components)
!   U(7:9)   d2
!   U(10:12) d3
!   U(13:15) n        internal force  (material components n_i = n.d_i)
!   U(16:18) m        internal moment (material components)
! Strains u = (m1, m2/K2, m3/K3);  r' = d3,  d_i' = u x d_i,
!   n' = n x u,  m' = m x u + n x e3   (material components).
! This is the same system as knotrod's src/model/shooting.rs (rhs_loaded).
!
! Parameters:
!   PAR(1) PHI   = phi/(2 pi), end rotation (continuation parameter)
!   PAR(2) ZSTAR = z*,  PAR(3) DELTA = delta,  PAR(4) K2,  PAR(5) K3
!   PAR(6) HOM   homotopy 0 -> 1 used only by the polishing run: the s = 1
!                conditions are G(U(1)) - (1 - HOM) G0, G0 = PAR(21:26) the
!                mismatch of the unpolished shooting start (0 once polished).
! Boundary conditions (NBC = 18):
!   s = 0: r = 0, d1 = e1, d2 = e2, d3 = e3                       (12)
!   s = 1: r = r* = (-delta cos(phi/2), -delta sin(phi/2), z*)   (3)
!          d3x = 0, d3y = 0, d1 . (-sin phi, cos phi, 0) = 0     (3)
!---------------------------------------------------------------------------

SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC
  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)
  DOUBLE PRECISION d1(3), d2(3), d3(3), n(3), m(3), uu(3), c(3)
  INTEGER i

  d1 = U(4:6); d2 = U(7:9); d3 = U(10:12); n = U(13:15); m = U(16:18)
  c = (/ 1d0, 1d0/PAR(4), 1d0/PAR(5) /)
  uu = c*m

  F(1:3)   = d3
  F(4:6)   = uu(3)*d2 - uu(2)*d3
  F(7:9)   = uu(1)*d3 - uu(3)*d1
  F(10:12) = uu(2)*d1 - uu(1)*d2
  F(13:15) = cross(n, uu)
  F(16:18) = cross(m, uu) + (/ n(2), -n(1), 0d0 /)

  IF (IJAC == 0) RETURN
  DFDU = 0d0
  DO i = 1, 3
     DFDU(i, 9+i) = 1d0                                  ! r' = d3
     DFDU(3+i, 6+i) = uu(3); DFDU(3+i, 9+i) = -uu(2)     ! d1'
     DFDU(3+i, 17) = -c(2)*d3(i); DFDU(3+i, 18) = c(3)*d2(i)
     DFDU(6+i, 9+i) = uu(1); DFDU(6+i, 3+i) = -uu(3)     ! d2'
     DFDU(6+i, 16) = d3(i); DFDU(6+i, 18) = -c(3)*d1(i)
     DFDU(9+i, 3+i) = uu(2); DFDU(9+i, 6+i) = -uu(1)     ! d3'
     DFDU(9+i, 17) = c(2)*d1(i); DFDU(9+i, 16) = -d2(i)
  END DO
  ! n' = n x u:  d/dn = -[u]x,  d/dm = [n]x diag(c)
  DFDU(13:15, 13:15) = -skew(uu)
  DFDU(13:15, 16:18) = skew(n)*SPREAD(c, 1, 3)
  ! m' = m x u + n x e3
  DFDU(16:18, 16:18) = -skew(uu) + skew(m)*SPREAD(c, 1, 3)
  DFDU(16, 14) = 1d0; DFDU(17, 13) = -1d0

  IF (IJAC == 1) RETURN
  DFDP(:, 1:6) = 0d0  ! K2, K3 derivatives are not needed (never continued)

CONTAINS
  FUNCTION cross(a, b)
    DOUBLE PRECISION, INTENT(IN) :: a(3), b(3)
    DOUBLE PRECISION cross(3)
    cross = (/ a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1) /)
  END FUNCTION cross
  FUNCTION skew(a)
    DOUBLE PRECISION, INTENT(IN) :: a(3)
    DOUBLE PRECISION skew(3,3)
    skew = RESHAPE((/ 0d0, a(3), -a(2), -a(3), 0d0, a(1), a(2), -a(1), 0d0 /), (/3,3/))
  END FUNCTION skew
END SUBROUTINE FUNC

SUBROUTINE STPNT(NDIM,U,PAR,T)
  ! The start is read from rod.dat (made by run_auto.py); only parameters here.
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM
  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(IN) :: T
  PAR(1) = 0.802d0
  PAR(2) = 0.115d0
  PAR(3) = 0.05d0
  PAR(4) = 3d0
  PAR(5) = 3d0
  PAR(6) = 1d0
END SUBROUTINE STPNT

SUBROUTINE BCND(NDIM,PAR,ICP,NBC,U0,U1,FB,IJAC,DBC)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM, ICP(*), NBC, IJAC
  DOUBLE PRECISION, INTENT(IN) :: PAR(*), U0(NDIM), U1(NDIM)
  DOUBLE PRECISION, INTENT(OUT) :: FB(NBC)
  DOUBLE PRECISION, INTENT(INOUT) :: DBC(NBC,*)
  DOUBLE PRECISION, PARAMETER :: PI = 3.14159265358979323846d0
  DOUBLE PRECISION phi, hom
  INTEGER i

  phi = 2d0*PI*PAR(1)
  hom = 1d0 - PAR(6)
  FB(1:3) = U0(1:3)
  FB(4:12) = U0(4:12) - (/ 1d0,0d0,0d0, 0d0,1d0,0d0, 0d0,0d0,1d0 /)
  FB(13) = U1(1) + PAR(3)*COS(phi/2d0) - hom*PAR(21)
  FB(14) = U1(2) + PAR(3)*SIN(phi/2d0) - hom*PAR(22)
  FB(15) = U1(3) - PAR(2)              - hom*PAR(23)
  FB(16) = U1(10)                      - hom*PAR(24)
  FB(17) = U1(11)                      - hom*PAR(25)
  FB(18) = -SIN(phi)*U1(4) + COS(phi)*U1(5) - hom*PAR(26)

  IF (IJAC == 0) RETURN
  DBC(1:NBC, 1:2*NDIM) = 0d0
  DO i = 1, 12
     DBC(i, i) = 1d0
  END DO
  DBC(13, NDIM+1) = 1d0
  DBC(14, NDIM+2) = 1d0
  DBC(15, NDIM+3) = 1d0
  DBC(16, NDIM+10) = 1d0
  DBC(17, NDIM+11) = 1d0
  DBC(18, NDIM+4) = -SIN(phi)
  DBC(18, NDIM+5) = COS(phi)
  IF (IJAC == 1) RETURN
  DBC(1:NBC, 2*NDIM+1:2*NDIM+6) = 0d0
  DBC(13, 2*NDIM+1) = -PAR(3)*SIN(phi/2d0)*PI
  DBC(14, 2*NDIM+1) = PAR(3)*COS(phi/2d0)*PI
  DBC(18, 2*NDIM+1) = 2d0*PI*(-COS(phi)*U1(4) - SIN(phi)*U1(5))
  DBC(13, 2*NDIM+3) = COS(phi/2d0)
  DBC(14, 2*NDIM+3) = SIN(phi/2d0)
  DBC(15, 2*NDIM+2) = -1d0
  DO i = 1, 6
     DBC(12+i, 2*NDIM+6) = PAR(20+i)
  END DO
END SUBROUTINE BCND

SUBROUTINE ICND
END SUBROUTINE ICND

SUBROUTINE FOPT
END SUBROUTINE FOPT

SUBROUTINE PVLS
END SUBROUTINE PVLS
