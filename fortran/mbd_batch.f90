!> mbd_batch: one analysis over many parameter sets (design sweeps) in one call.
!!
!! The model's flat tables (mbd_model) are given once. For each case c the entries named in
!! vtab(2, nv) take the values vals(:, c); vtab addresses an entry as a design parameter is
!! addressed (mbd_sensitivity): table 1 rpar, 2 bmass (flattened (2, nb)), 3 grav, 4 fpar, and
!! the 1-based index in it. Phases left open in the description (rack-pinion, rolling disc)
!! are then set again so that their equation holds at the q0 estimates, as the front end
!! does when it packs a model (its phase row of Phi at (q0, q_dot = 0, t = 0) with the phase
!! set to 0). The analysis then runs through mbd_api on the tables so changed: the model is
!! rebuilt from them (its length scale, every prepared parameter: unit axes, spline
!! coefficients, gear geometry), so a case gives the numbers a run of its own tables gives,
!! bit for bit.
!!
!! Outputs are per case (last dimension); a failing case keeps its status, message and the
!! rows it computed, and the next case runs. With a list of mechanism measures (mbd_measures:
!! transmission angles, ratios, the distance to a dead centre) each case also gets them at
!! its rows, from its own tables (an angle's points may be entries the case sets).
module mbd_batch
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MBD_BAD_SETTING, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_fail
  use mbd_api, only: NINFO, api_kinematics, api_inverse, api_statics, api_dynamics, api_eval, &
                     api_dynamics_sens, api_modes, api_frf
  use mbd_kinematics, only: MAXPASS
  use mbd_contact, only: NEO
  use mbd_measures, only: api_measures
  use mbd_integrators, only: METH_DOPRI5, METH_GENALPHA
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  implicit none
  private
  public :: batch_run, NISET, NRSET
  public :: BATCH_KINEMATICS, BATCH_INVERSE, BATCH_STATICS, BATCH_DYNAMICS, BATCH_MODES, &
            BATCH_FRF

  !> analyses
  integer, parameter :: BATCH_KINEMATICS = 1, BATCH_INVERSE = 2, BATCH_STATICS = 3, &
                        BATCH_DYNAMICS = 4, BATCH_MODES = 5, BATCH_FRF = 6
  !> settings: iset = [nsteps, maxit, every, solver, method, max_steps, positions, at_q0]
  !! (positions: 1 = kinematics of the positions alone, qdout and qddout (nq, 0, ncase);
  !! at_q0: modes and the frequency response about the assembled q0, not the equilibrium);
  !! rset = [t0, t1, tol, tmin, rtol, atol, h, rho_inf, alpha, beta, t (statics, modes, frf), 0]
  integer, parameter :: NISET = 8, NRSET = 12

contains

  !> Run the analysis for every case. Output shapes: qout, qdout, qddout (nq, rows, ncase;
  !! qdout, qddout (nq, 0, ncase) for positions-only kinematics),
  !! lamout (neq or 0, rows, ncase), eout (4 or 0, rows, ncase); iinfo, rinfo (NINFO, ncase)
  !! as the analysis reports them (statics: rinfo(1) residual, rinfo(2) stability code);
  !! qsing (nq, ncase), dep and redundant (neq, ncase). Statics writes row 1.
  !! Modes (api_modes; rows = the modes asked for): qout the shapes (nq, modes, ncase),
  !! qdout and qddout (nq, 0, ncase), lamout (0, modes, ncase), eout (6, modes, ncase) per
  !! mode k [omega^2, kind, s(2k - 1) re, im, s(2k) re, im] (the damped eigenvalues),
  !! qsing the equilibrium, iinfo(1) the free motions, rinfo(1:2) as statics.
  !! Frequency response (api_frf; rows = the angular frequencies, given in times (rows),
  !! rad/s; the inputs are the design parameters of ptab): sq and sqd the response's real
  !! and imaginary parts (nq, np, rows, ncase), sqdd zero, slam (2 neq, np, rows, ncase) the
  !! multipliers' response, real parts then imaginary (or (0, np, rows, ncase): none); qout
  !! zero, qdout and qddout (nq, 0, ncase), lamout and eout (0, rows, ncase); qsing the
  !! equilibrium, iinfo(1) the free motions, iinfo(8) a frequency at which the response is
  !! unbounded, rinfo(1:2) as statics. No measures.
  !! Measures (all or none of the optional arguments; none given or an empty list: no
  !! measures; not with statics): mkind, mint, mpts,
  !! mref as api_measures takes them, times (rows) the output times; mout (nm, rows, ncase)
  !! gets them at the rows up to the first that is not finite, and mbad (3, ncase) the
  !! status, measure and quantity of a case whose measures failed (its message too, when
  !! its analysis succeeded).
  !! Design sensitivities (ptab (2, np) as mbd_sensitivity takes it, with sq, sqd, sqdd
  !! (nq, np, rows, ncase) and slam (neq, or 0 for kinematics, np, rows, ncase); not with
  !! positions-only kinematics; dynamics by dopri5 or generalized-alpha): each case's, as a
  !! single run of its tables gives them.
  !! With both, mdout gets the measures' design derivatives (api_measures).
  subroutine batch_run(analysis, nb, ctab, rpar, bmass, grav, ftab, fpar, q0, v0, vtab, vals, &
                       opens, iset, rset, qout, qdout, qddout, lamout, eout, iinfo, rinfo, &
                       qsing, dep, redundant, status, msg, times, mkind, mint, mpts, mref, &
                       mout, mbad, ptab, sq, sqd, sqdd, slam, mdout)
    integer, intent(in) :: analysis             !! BATCH_KINEMATICS ... BATCH_FRF
    integer, intent(in) :: nb                   !! moving bodies
    integer, intent(in) :: ctab(:, :), ftab(:, :)  !! constraint and force tables
    real(wp), intent(in) :: rpar(:), bmass(:, :), grav(2), fpar(:)  !! the model's numbers
    real(wp), intent(in) :: q0(:), v0(:)        !! estimates and initial velocities (nq)
    integer, intent(in) :: vtab(:, :)           !! (2, nv) the entries each case sets
    real(wp), intent(in) :: vals(:, :)          !! (nv, ncase) their values
    !> (2, no) open phases: their index in rpar and their row of Phi
    integer, intent(in) :: opens(:, :)
    integer, intent(in) :: iset(NISET)          !! integer settings (see NISET)
    real(wp), intent(in) :: rset(NRSET)         !! real settings (see NRSET)
    real(wp), intent(out) :: qout(:, :, :), qdout(:, :, :), qddout(:, :, :)
    real(wp), intent(out) :: lamout(:, :, :), eout(:, :, :)
    integer, intent(out) :: iinfo(:, :)         !! (NINFO, ncase)
    real(wp), intent(out) :: rinfo(:, :)        !! (NINFO, ncase)
    real(wp), intent(out) :: qsing(:, :)        !! (nq, ncase)
    integer, intent(out) :: dep(:, :), redundant(:, :)  !! (neq, ncase)
    integer, intent(out) :: status(:)           !! (ncase) each case's status
    character(len=MSG_LEN), intent(out) :: msg(:)  !! (ncase) and message
    real(wp), intent(in), optional :: times(:)  !! (rows) output times
    integer, intent(in), optional :: mkind(:), mint(:, :), mref(:, :, :)  !! measures
    real(wp), intent(in), optional :: mpts(:, :, :)  !! an angle's points
    real(wp), intent(out), optional :: mout(:, :, :)  !! (nm, rows, ncase)
    integer, intent(out), optional :: mbad(:, :)  !! (3, ncase)
    integer, intent(in), optional :: ptab(:, :)   !! (2, np) design parameters
    !> (nq, np, rows, ncase) dq/dp, dq_dot/dp, dq_ddot/dp; (neq or 0, np, rows, ncase)
    !! dlambda/dp (inverse dynamics, statics)
    real(wp), intent(out), optional, contiguous :: sq(:, :, :, :), sqd(:, :, :, :), &
                                                   sqdd(:, :, :, :), slam(:, :, :, :)
    !> (nm, np, rows, ncase) the measures' design derivatives (with measures and
    !! sensitivities), at the rows whose states and sensitivities are finite
    real(wp), intent(out), optional :: mdout(:, :, :, :)
    real(wp), allocatable :: r(:), bm(:, :), fp(:), phi(:), jac(:, :), nu(:), gam(:), zq(:)
    real(wp), allocatable :: eo(:, :, :)      ! element outputs of a dynamics case (not kept)
    ! a modes case's omega^2, kinds, damped eigenvalues and multipliers
    real(wp), allocatable :: w2(:), sre(:), sim(:), lamw(:)
    integer, allocatable :: kinds(:)
    real(wp) :: g(2), tpass(MAXPASS), resid, evo(4, 1)
    integer :: c, k, nq, neq, ncase, st, bad, stable, ierr, nev, nr, mb(2)
    logical :: meas, sens, dmeas
    character(len=MSG_LEN) :: lmsg
    qout = zero; qdout = zero; qddout = zero; lamout = zero; eout = zero
    iinfo = 0; rinfo = zero; qsing = zero; dep = 0; redundant = 0
    ncase = size(vals, 2); nq = size(q0); neq = size(dep, 1)
    status = MBD_OK; msg = ''
    meas = present(times) .and. present(mkind) .and. present(mint) .and. present(mpts) .and. &
           present(mref) .and. present(mout) .and. present(mbad)
    if (meas) then
      mout = zero; mbad = 0
      meas = size(mkind) > 0
    end if
    sens = present(ptab) .and. present(sq) .and. present(sqd) .and. present(sqdd) .and. &
           present(slam)
    if (sens) then
      sq = zero; sqd = zero; sqdd = zero; slam = zero
      sens = size(ptab, 2) > 0
    end if
    dmeas = meas .and. sens .and. present(mdout)
    if (dmeas) mdout = zero
    call check(st, lmsg)
    if (st /= MBD_OK) then
      status = st; msg = lmsg; return
    end if
    allocate (r(size(rpar)), bm(size(bmass, 1), size(bmass, 2)), fp(size(fpar)), stat=ierr)
    if (ierr == 0 .and. size(opens, 2) > 0) &
      allocate (phi(neq), jac(neq, nq), nu(neq), gam(neq), zq(nq), stat=ierr)
    if (ierr == 0) allocate (eo(NEO, size(ftab, 2), size(qout, 2)), stat=ierr)
    if (ierr == 0 .and. analysis == BATCH_FRF) allocate (lamw(neq), stat=ierr)
    if (ierr == 0 .and. analysis == BATCH_MODES) allocate (w2(size(qout, 2)), &
      kinds(size(qout, 2)), sre(2 * size(qout, 2)), sim(2 * size(qout, 2)), lamw(neq), &
      stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * (size(rpar) + size(bmass) + size(fpar) + &
                    real(neq, wp) * (nq + 3) + real(NEO, wp) * size(ftab, 2) * size(qout, 2)), &
                    'the tables of a case', 'use a smaller model', &
                    st, lmsg)
      status = st; msg = lmsg; return
    end if
    do c = 1, ncase
      r = rpar; bm = bmass; g = grav; fp = fpar
      do k = 1, size(vtab, 2)
        select case (vtab(1, k))
        case (1); r(vtab(2, k)) = vals(k, c)
        case (2); bm(2 - mod(vtab(2, k), 2), (vtab(2, k) + 1) / 2) = vals(k, c)
        case (3); g(vtab(2, k)) = vals(k, c)
        case default; fp(vtab(2, k)) = vals(k, c)
        end select
      end do
      if (size(opens, 2) > 0) then
        ! as packing does: the phase row of Phi at (q0, 0, t = 0) with the phase set to 0
        zq = zero
        r(opens(1, :)) = zero
        call api_eval(nb, ctab, r, q0, zq, zero, phi, jac, nu, gam, st, lmsg, bad)
        r(opens(1, :)) = phi(opens(2, :))
      end if
      if (sens) then
        call run_case(c, ptab, sq(:, :, :, c), sqd(:, :, :, c), sqdd(:, :, :, c), &
                      slam(:, :, :, c))
      else
        call run_case(c)
      end if
      if (meas .and. iinfo(1, c) > 0) then   ! the rows up to the first that is not finite
        nr = 0
        do while (nr < min(iinfo(1, c), size(qout, 2)))
          if (.not. all(ieee_is_finite(qout(:, nr + 1, c)))) exit
          if (dmeas) then
            if (.not. all(ieee_is_finite(sq(:, :, nr + 1, c)))) exit
          end if
          nr = nr + 1
        end do
        if (dmeas) then
          call api_measures(nb, ctab, r, qout(:, 1:nr, c), times(1:nr), mkind, mint, mpts, &
                            mref, mout(:, 1:nr, c), mb, st, lmsg, ptab, sq(:, :, 1:nr, c), &
                            mdout(:, :, 1:nr, c))
        else
          call api_measures(nb, ctab, r, qout(:, 1:nr, c), times(1:nr), mkind, mint, mpts, &
                            mref, mout(:, 1:nr, c), mb, st, lmsg)
        end if
        if (st /= MBD_OK) then
          mbad(:, c) = [st, mb]
          if (status(c) == MBD_OK) msg(c) = lmsg
        end if
      end if
    end do

  contains

    !> Case c's analysis, as a single run of its tables; with the parameter table pt, also
    !! its sensitivities s1, s2, s3 (q, q_dot, q_ddot; (nq, np, rows)) and sl (the
    !! multipliers'), as that run gives them (dynamics: dopri5 with the variational
    !! equations, or generalized-alpha's discrete ones).
    subroutine run_case(c, pt, s1, s2, s3, sl)
      integer, intent(in) :: c
      integer, intent(in), optional :: pt(:, :)
      real(wp), intent(out), optional, contiguous :: s1(:, :, :), s2(:, :, :), s3(:, :, :), &
                                                     sl(:, :, :)
      select case (analysis)
      ! (absent contiguous arrays are not passed on: gfortran reads their descriptors, and
      ! UBSan flags the loads)
      case (BATCH_KINEMATICS)
        if (present(pt)) then
          call api_kinematics(nb, ctab, r, q0, rset(1), rset(2), iset(1), rset(3), iset(2), &
                              rset(4), iset(3), iset(4), qout(:, :, c), qdout(:, :, c), &
                              qddout(:, :, c), iinfo(:, c), rinfo(:, c), qsing(:, c), &
                              dep(:, c), redundant(:, c), tpass, status(c), msg(c), pt, s1, &
                              s2, s3, positions=iset(7))
        else
          call api_kinematics(nb, ctab, r, q0, rset(1), rset(2), iset(1), rset(3), iset(2), &
                              rset(4), iset(3), iset(4), qout(:, :, c), qdout(:, :, c), &
                              qddout(:, :, c), iinfo(:, c), rinfo(:, c), qsing(:, c), &
                              dep(:, c), redundant(:, c), tpass, status(c), msg(c), &
                              positions=iset(7))
        end if
      case (BATCH_INVERSE)
        if (present(pt)) then
          call api_inverse(nb, ctab, r, bm, g, ftab, fp, q0, rset(1), rset(2), iset(1), &
                           rset(3), iset(3), iset(4), qout(:, :, c), qdout(:, :, c), &
                           qddout(:, :, c), lamout(:, :, c), eout(:, :, c), iinfo(:, c), &
                           rinfo(:, c), qsing(:, c), dep(:, c), redundant(:, c), tpass, &
                           status(c), msg(c), pt, s1, s2, s3, sl)
        else
          call api_inverse(nb, ctab, r, bm, g, ftab, fp, q0, rset(1), rset(2), iset(1), &
                           rset(3), iset(3), iset(4), qout(:, :, c), qdout(:, :, c), &
                           qddout(:, :, c), lamout(:, :, c), eout(:, :, c), iinfo(:, c), &
                           rinfo(:, c), qsing(:, c), dep(:, c), redundant(:, c), tpass, &
                           status(c), msg(c))
        end if
      case (BATCH_STATICS)
        if (present(pt)) then          ! (one output row: the sensitivities' first)
          call api_statics(nb, ctab, r, bm, g, ftab, fp, q0, rset(11), qout(:, 1, c), &
                           lamout(:, 1, c), stable, resid, iinfo(:, c), status(c), msg(c), &
                           pt, s1(:, :, 1), sl(:, :, 1))
        else
          call api_statics(nb, ctab, r, bm, g, ftab, fp, q0, rset(11), qout(:, 1, c), &
                           lamout(:, 1, c), stable, resid, iinfo(:, c), status(c), msg(c))
        end if
        rinfo(1, c) = resid; rinfo(2, c) = real(stable, wp)
      case (BATCH_MODES)
        call api_modes(nb, ctab, r, bm, g, ftab, fp, q0, rset(11), merge(0, 1, iset(8) == 1), &
                       size(qout, 2), qsing(:, c), lamw, stable, resid, w2, kinds, sre, sim, &
                       qout(:, :, c), iinfo(:, c), status(c), msg(c), iset(4))
        do k = 1, size(qout, 2)
          eout(:, k, c) = [w2(k), real(kinds(k), wp), sre(2 * k - 1), sim(2 * k - 1), &
                           sre(2 * k), sim(2 * k)]
        end do
        rinfo(1, c) = resid; rinfo(2, c) = real(stable, wp)
      case (BATCH_FRF)                 ! (check: pt and times present)
        if (size(sl, 1) > 0) then      ! (and the multipliers' response)
          call api_frf(nb, ctab, r, bm, g, ftab, fp, q0, rset(11), merge(0, 1, iset(8) == 1), &
                       pt, times, qsing(:, c), lamw, stable, resid, s1, s2, iinfo(:, c), &
                       status(c), msg(c), iset(4), sl(1:neq, :, :), sl(neq + 1:, :, :))
        else
          call api_frf(nb, ctab, r, bm, g, ftab, fp, q0, rset(11), merge(0, 1, iset(8) == 1), &
                       pt, times, qsing(:, c), lamw, stable, resid, s1, s2, iinfo(:, c), &
                       status(c), msg(c), iset(4))
        end if
        rinfo(1, c) = resid; rinfo(2, c) = real(stable, wp)
      case default
        if (present(pt)) then
          call api_dynamics_sens(nb, ctab, r, bm, g, ftab, fp, q0, v0, rset(1), rset(2), &
                                 iset(1), rset(5), rset(6), iset(3), iset(6), pt, &
                                 qout(:, :, c), qdout(:, :, c), qddout(:, :, c), &
                                 lamout(:, :, c), eout(:, :, c), s1, s2, s3, sl, iinfo(:, c), &
                                 rinfo(:, c), redundant(:, c), status(c), msg(c), &
                                 method=iset(5), h=rset(7), rho_inf=rset(8))
        else
          call api_dynamics(nb, ctab, r, bm, g, ftab, fp, q0, v0, rset(1), rset(2), iset(1), &
                            iset(5), rset(5), rset(6), rset(7), rset(8), rset(9), rset(10), &
                            iset(3), qout(:, :, c), qdout(:, :, c), qddout(:, :, c), &
                            lamout(:, :, c), eout(:, :, c), iinfo(:, c), rinfo(:, c), &
                            redundant(:, c), status(c), msg(c), iset(6), eo, evo, nev)
        end if
      end select
    end subroutine run_case

    !> The tables and output shapes agree with each other (a wrong call is refused whole).
    subroutine check(st, text)
      integer, intent(out) :: st
      character(len=MSG_LEN), intent(out) :: text
      integer :: j, n(4), nrow
      logical :: positions, wrong
      st = MBD_BAD_INPUT; text = ''
      positions = (analysis == BATCH_KINEMATICS .and. iset(7) == 1) .or. &
                  analysis == BATCH_MODES .or. analysis == BATCH_FRF   ! (no velocity rows)
      n = [size(rpar), size(bmass), 2, size(fpar)]
      nrow = size(qout, 2)
      if (analysis < BATCH_KINEMATICS .or. analysis > BATCH_FRF) then
        text = 'batch: unknown analysis'; st = MBD_BAD_SETTING; return
      end if
      if (size(vtab, 1) /= 2 .or. size(vals, 1) /= size(vtab, 2) .or. size(opens, 1) /= 2) then
        text = 'batch: the value table and the values do not match'; return
      end if
      do j = 1, size(vtab, 2)
        if (vtab(1, j) < 1 .or. vtab(1, j) > 4) then
          text = 'batch: a value table entry names no table'; return
        end if
        if (vtab(2, j) < 1 .or. vtab(2, j) > n(vtab(1, j))) then
          text = 'batch: a value table index is out of range'; return
        end if
      end do
      if (any(opens(1, :) < 1) .or. any(opens(1, :) > size(rpar)) .or. &
          any(opens(2, :) < 1) .or. any(opens(2, :) > neq)) then
        text = 'batch: an open phase is out of range'; return
      end if
      if (size(v0) /= nq .or. any(shape(qddout) /= shape(qdout)) .or. &
          size(qdout, 1) /= nq .or. size(qdout, 3) /= ncase .or. &
          size(qdout, 2) /= merge(0, nrow, positions) .or. size(qout, 1) /= nq .or. &
          size(qout, 3) /= ncase .or. size(lamout, 2) /= nrow .or. &
          size(lamout, 3) /= ncase .or. size(eout, 2) /= nrow .or. size(eout, 3) /= ncase .or. &
          size(iinfo, 1) /= NINFO .or. size(iinfo, 2) /= ncase .or. &
          any(shape(rinfo) /= shape(iinfo)) .or. size(qsing, 1) /= nq .or. &
          size(qsing, 2) /= ncase .or. size(dep, 2) /= ncase .or. &
          any(shape(redundant) /= shape(dep)) .or. size(status) /= ncase .or. &
          size(msg) /= ncase) then
        text = 'batch: output arrays do not match'; return
      end if
      if (analysis == BATCH_MODES) then
        if (size(lamout, 1) /= 0 .or. size(eout, 1) /= 6 .or. meas .or. sens) then
          text = 'batch: the modes'' arrays do not match (no measures or sensitivities)'
          return
        end if
      else if (analysis == BATCH_FRF) then
        wrong = size(lamout, 1) /= 0 .or. size(eout, 1) /= 0 .or. meas .or. .not. sens .or. &
                .not. present(times)
        if (.not. wrong) wrong = size(times) /= nrow
        if (wrong) then
          text = 'batch: the frequency response''s arrays do not match (its inputs as the ' &
                 // 'sensitivities'' parameters, the frequencies as the times, no measures)'
          return
        end if
      else if (analysis /= BATCH_KINEMATICS .and. (size(lamout, 1) /= neq .or. &
               size(eout, 1) /= 4)) then
        text = 'batch: multiplier or energy arrays do not match'; return
      end if
      if (analysis == BATCH_STATICS .and. nrow /= 1) then
        text = 'batch: statics has one output row'; return
      end if
      if (sens) then
        if (any(shape(sq) /= [nq, size(ptab, 2), nrow, ncase]) .or. size(ptab, 1) /= 2 .or. &
            any(shape(sqd) /= shape(sq)) .or. any(shape(sqdd) /= shape(sq)) .or. &
            (positions .and. analysis /= BATCH_FRF) .or. (size(slam, 1) /= &
            merge(0, neq, analysis == BATCH_KINEMATICS .or. analysis == BATCH_FRF) .and. &
            .not. (analysis == BATCH_FRF .and. size(slam, 1) == 2 * neq)) .or. &
            size(slam, 2) /= size(ptab, 2) .or. size(slam, 3) /= nrow .or. &
            size(slam, 4) /= ncase .or. (analysis == BATCH_DYNAMICS .and. &
            iset(5) /= METH_DOPRI5 .and. iset(5) /= METH_GENALPHA)) then
          text = 'batch: sensitivity arrays do not match'; return
        end if
      end if
      if (meas) then
        if (analysis == BATCH_STATICS .or. size(times) /= nrow .or. &
            size(mout, 1) /= size(mkind) .or. size(mout, 2) /= nrow .or. &
            size(mout, 3) /= ncase .or. size(mbad, 1) /= 3 .or. size(mbad, 2) /= ncase) then
          text = 'batch: measure arrays do not match'; return
        end if
      end if
      if (dmeas) then
        if (any(shape(mdout) /= [size(mkind), size(ptab, 2), nrow, ncase])) then
          text = 'batch: measure derivative arrays do not match'; return
        end if
      end if
      st = MBD_OK
    end subroutine check

  end subroutine batch_run

end module mbd_batch
