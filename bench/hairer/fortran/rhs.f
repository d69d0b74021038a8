C     Right-hand sides of the two benchmark problems, in the calling
C     convention of DOP853 and DOPRI5: FCN(N,X,Y,F,RPAR,IPAR).
C     The Rust side (src/problems.rs) evaluates the same expressions
C     in the same order, so both integrate the same field.
C
C     FAREN: the restricted three-body problem (Arenstorf orbit),
C     Hairer, Norsett, Wanner, Solving ODEs I, Section II.0, (0.1):
C       Y = (y1, y2, y1', y2'),  RPAR(1) = mu,  mu' = 1 - mu,
C       D1 = ((y1 + mu)**2 + y2**2)**(3/2),
C       D2 = ((y1 - mu')**2 + y2**2)**(3/2),
C       y1'' = y1 + 2 y2' - mu' (y1 + mu) / D1 - mu (y1 - mu') / D2,
C       y2'' = y2 - 2 y1' - mu' y2 / D1 - mu y2 / D2.
      SUBROUTINE FAREN(N,X,Y,F,RPAR,IPAR)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION Y(N),F(N),RPAR(*),IPAR(*)
      AMU=RPAR(1)
      AMUP=1.D0-AMU
      F(1)=Y(3)
      F(2)=Y(4)
      R1=(Y(1)+AMU)**2+Y(2)**2
      R1=R1*SQRT(R1)
      R2=(Y(1)-AMUP)**2+Y(2)**2
      R2=R2*SQRT(R2)
      F(3)=Y(1)+2.D0*Y(4)-AMUP*(Y(1)+AMU)/R1-AMU*(Y(1)-AMUP)/R2
      F(4)=Y(2)-2.D0*Y(3)-AMUP*Y(2)/R1-AMU*Y(2)/R2
      RETURN
      END
C
C     FPART: a particle in the field (0, -g) under the constant-speed
C     constraint vx**2 + vy**2 = v0**2, multiplier eliminated by hand:
C       Y = (x, y, vx, vy),  RPAR(1) = g,
C       a = gv - (gv . v) v / |v|**2,  gv = (0, -g),
C     i.e. with c = g vy / |v|**2:  x'' = c vx,  y'' = -g + c vy.
      SUBROUTINE FPART(N,X,Y,F,RPAR,IPAR)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION Y(N),F(N),RPAR(*),IPAR(*)
      G=RPAR(1)
      F(1)=Y(3)
      F(2)=Y(4)
      V2=Y(3)*Y(3)+Y(4)*Y(4)
      C=G*Y(4)/V2
      F(3)=C*Y(3)
      F(4)=-G+C*Y(4)
      RETURN
      END
C
C     SOLOUT for IOUT=0: never called by either code.
      SUBROUTINE SOLDUM(NR,XOLD,X,Y,N,CON,ICOMP,ND,RPAR,IPAR,IRTRN,
     &                  XOUT)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DIMENSION Y(N),CON(*),ICOMP(*),RPAR(*),IPAR(*)
      RETURN
      END
