! One solve of a benchmark problem with DOP853 or DOPRI5, callable from C (and Rust).
!
! The right-hand side is the Fortran FAREN or FPART of rhs.f, so the integrator calls it
! Fortran to Fortran, exactly as in Hairer's own drivers; the caller crosses the language
! boundary once per solve, not once per evaluation.
!
! Settings: ITOL = 0 (scalar rtol, atol), IOUT = 0 (no output routine, no dense output), every
! WORK/IWORK parameter at its default except IWORK(1) (step limit, 1 000 000 as in chetaev's
! default) and IWORK(3) = -1 (print nothing).
subroutine hairer_solve(method, problem, n, t0, t1, y, rpar, rtol, atol, counts, idid) &
        bind(c, name="hairer_solve")
    use iso_c_binding, only: c_int, c_double
    implicit none
    !> 1 = DOP853, 2 = DOPRI5.
    integer(c_int), value, intent(in) :: method
    !> 1 = Arenstorf (FAREN), 2 = constant-speed particle (FPART).
    integer(c_int), value, intent(in) :: problem
    integer(c_int), value, intent(in) :: n
    real(c_double), value, intent(in) :: t0, t1, rtol, atol
    !> In: the initial state; out: the state at t1.
    real(c_double), intent(inout) :: y(n)
    !> The problem's parameters (RPAR).
    real(c_double), intent(in) :: rpar(*)
    !> Out: NFCN, NSTEP, NACCPT, NREJCT.
    integer(c_int), intent(out) :: counts(4)
    !> Out: IDID of the code (1 = success); -10 for an unknown method or problem, or n > 16.
    integer(c_int), intent(out) :: idid

    external :: dop853, dopri5, faren, fpart, soldum
    !> Largest dimension: the work arrays are fixed, as in Hairer's own drivers (no allocation).
    integer, parameter :: nmax = 16, lwork = 11 * nmax + 21, liwork = 21
    double precision :: x, xend, rt(1), at(1), work(lwork)
    integer :: iwork(liwork), ipar(1)

    idid = -10
    counts(:) = 0
    if (n < 1 .or. n > nmax) return
    work(1:20) = 0.0d0
    iwork(:) = 0
    iwork(1) = 1000000
    iwork(3) = -1
    ipar(1) = 0
    x = t0
    xend = t1
    rt(1) = rtol
    at(1) = atol
    if (method == 1 .and. problem == 1) then
        call dop853(n, faren, x, y, xend, rt, at, 0, soldum, 0, work, lwork, iwork, liwork, &
            rpar, ipar, idid)
    else if (method == 1 .and. problem == 2) then
        call dop853(n, fpart, x, y, xend, rt, at, 0, soldum, 0, work, lwork, iwork, liwork, &
            rpar, ipar, idid)
    else if (method == 2 .and. problem == 1) then
        call dopri5(n, faren, x, y, xend, rt, at, 0, soldum, 0, work, lwork, iwork, liwork, &
            rpar, ipar, idid)
    else if (method == 2 .and. problem == 2) then
        call dopri5(n, fpart, x, y, xend, rt, at, 0, soldum, 0, work, lwork, iwork, liwork, &
            rpar, ipar, idid)
    else
        return
    end if
    counts(1) = iwork(17)
    counts(2) = iwork(18)
    counts(3) = iwork(19)
    counts(4) = iwork(20)
end subroutine hairer_solve

! The right-hand sides on their own, for the test that the Rust ones agree with them.
subroutine hairer_rhs(problem, n, t, y, rpar, f) bind(c, name="hairer_rhs")
    use iso_c_binding, only: c_int, c_double
    implicit none
    integer(c_int), value, intent(in) :: problem, n
    real(c_double), value, intent(in) :: t
    real(c_double), intent(in) :: y(n), rpar(*)
    real(c_double), intent(out) :: f(n)
    external :: faren, fpart
    integer :: ipar(1)
    double precision :: x
    ipar(1) = 0
    x = t
    f(:) = 0.0d0
    if (problem == 1) then
        call faren(n, x, y, f, rpar, ipar)
    else if (problem == 2) then
        call fpart(n, x, y, f, rpar, ipar)
    end if
end subroutine hairer_rhs
