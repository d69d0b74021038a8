! The reference state of the Arenstorf benchmark: the exact solution, at the double-precision end
! time, of the problem as the benchmark poses it in double precision (the double-precision values
! of mu, y0 and T), integrated by DOP853 in quadruple precision at rtol = atol = 1e-25 and 1e-28.
!
! The closed orbit returns to y0 only for the 30-digit data of Hairer, Norsett and Wanner; the
! double-precision data differ from them by up to 1e-16, which the orbit amplifies to about
! 1.4e-11 after one period. This program measures that.
!
! Build and run (from bench/hairer/fortran; not part of the benchmark's build):
!   gfortran -O2 -std=legacy -freal-8-real-16 -c dop853.f rhs.f
!   gfortran -O2 -freal-8-real-16 reference_quad.f90 dop853.o rhs.o -o reference_quad
!   ./reference_quad
! -freal-8-real-16 promotes every DOUBLE PRECISION entity of Hairer's code to REAL(16); the
! sources are not changed. The literals below are the exact decimal values of the doubles
! 0.994, -2.00158510637908252240537862224, 17.0652165601579625588917206249 and 0.012277471.
program reference_quad
    implicit none
    integer, parameter :: n = 4, lwork = 11 * n + 21, liwork = 21
    double precision :: y(n), y0(n), x, t1, rt(1), at(1), work(lwork), rpar(1), tol(2)
    integer :: iwork(liwork), ipar(1), idid, k
    external :: dop853, faren, soldum

    y0 = [0.9939999999999999946709294817992486059665679931640625d0, 0d0, 0d0, &
        -2.001585106379082379390865753521211445331573486328125d0]
    t1 = 17.0652165601579639542251243256032466888427734375d0
    rpar(1) = 0.01227747099999999987052223815453544375486671924591064453125d0
    ipar(1) = 0
    tol = [1d-25, 1d-28]
    do k = 1, 2
        work = 0d0
        iwork = 0
        iwork(1) = 10000000
        iwork(3) = -1
        work(1) = 1d-33 ! the rounding unit of REAL(16)
        y = y0
        x = 0d0
        rt(1) = tol(k)
        at(1) = tol(k)
        call dop853(n, faren, x, y, t1, rt, at, 0, soldum, 0, work, lwork, iwork, liwork, &
            rpar, ipar, idid)
        print '(a, es8.1, a, i3, a, i8)', 'tol', tol(k), '  idid', idid, '  nfcn', iwork(17)
        print '(a, 4es42.33)', '  y(T)      ', y
        print '(a, 4es12.4)', '  y(T) - y0 ', y - y0
    end do
end program reference_quad
