!> mbd2d-solve: run a model file written by `mbd2d export`, without Python.
!!
!!   mbd2d-solve MODEL.mbd OUT.csv
!! Writes the CSV the Python path writes (t, then NAME.x ... NAME.theta_ddot per body).
!! Exit codes: 0 ok, 2 bad input (a malformed file, or counts too large for the memory),
!! 3 singular configuration (partial output written), 4 other numerical failure (partial
!! output written). Messages go to standard error, each starting "mbd2d-solve: ".
!! Nothing is allocated before the counts are checked (mbd_read) and the outputs, held in
!! memory, are checked against it (mem_check).
program mbd2d_solve
  use, intrinsic :: iso_fortran_env, only: error_unit
  use mbd_kinds, only: wp
  use mbd_status, only: MBD_OK, MBD_SINGULAR_CONFIG, MBD_NO_MEMORY, MSG_LEN
  use mbd_memory, only: REAL_BYTES, mem_check
  use mbd_mbdfile, only: mbd_spec_t, mbd_read
  use mbd_constraints, only: con_nrow
  use mbd_api, only: NINFO, api_sizes, api_kinematics
  use mbd_kinematics, only: MAXPASS
  implicit none
  type(mbd_spec_t) :: spec
  character(len=1024) :: model_path, out_path
  character(len=MSG_LEN) :: msg
  integer :: status, bad, nq, neq, k, iinfo(NINFO), ierr
  real(wp) :: rinfo(NINFO), bytes
  real(wp), allocatable :: q0(:), qout(:, :), qdout(:, :), qddout(:, :), qsing(:), tpass(:)
  integer, allocatable :: dep(:), redundant(:)

  if (command_argument_count() /= 2) then
    if (command_argument_count() == 1) then
      call get_command_argument(1, model_path)
      if (model_path == '-h' .or. model_path == '--help') then
        write (*, '(a)') 'usage: mbd2d-solve MODEL.mbd OUT.csv'
        write (*, '(a)') '  runs the analysis in a model file written by `mbd2d export` and '// &
          'writes a CSV'
        stop
      end if
    end if
    call die(2, 'usage: mbd2d-solve MODEL.mbd OUT.csv (runs the analysis in a model file '// &
             'written by `mbd2d export` and writes a CSV)')
  end if
  call get_command_argument(1, model_path)
  call get_command_argument(2, out_path)

  call mbd_read(trim(model_path), spec, status, msg)
  if (status /= MBD_OK) call die(2, trim(msg))
  if (spec%analysis /= 'kinematics') call die(2, 'analysis "' // trim(spec%analysis) // &
    '" is not supported by mbd2d-solve (kinematics only)')
  call api_sizes(spec%nb, spec%ctab, spec%rpar, nq, neq, status, msg, bad)
  if (status /= MBD_OK) call die(2, where(bad, msg))
  if (spec%steps_line == 0) call die(2, trim(model_path) // ': the file gives no "steps" line')

  ! the outputs (3 nq numbers per output time) are held in memory until the CSV is written
  bytes = REAL_BYTES * (3 * real(nq, wp) * (real(spec%steps, wp) + 1) + 2 * nq + 2 * neq)
  call mem_check(bytes, 'the outputs (3 x ' // trim(itoa(nq)) // ' numbers at ' // &
                 trim(itoa(spec%steps)) // ' + 1 times)', 'give fewer steps', status, msg)
  if (status /= MBD_OK) call die(2, trim(model_path) // ':' // trim(itoa(spec%steps_line)) // &
                                 ': ' // trim(msg))
  allocate (q0(nq), qsing(nq), dep(neq), redundant(neq), tpass(MAXPASS), stat=ierr)
  if (ierr == 0) allocate (qout(nq, spec%steps + 1), qdout(nq, spec%steps + 1), stat=ierr)
  if (ierr == 0) allocate (qddout(nq, spec%steps + 1), stat=ierr)
  if (ierr /= 0) call die(2, trim(model_path) // ':' // trim(itoa(spec%steps_line)) // &
                          ': not enough memory for the outputs of ' // trim(itoa(spec%steps)) // &
                          ' steps; give fewer steps')
  q0 = 0.0_wp
  q0(1:3 * spec%nb) = reshape(spec%q0, [3 * spec%nb])
  call api_kinematics(spec%nb, spec%ctab, spec%rpar, q0, spec%t0, spec%t_end, spec%steps, &
                      spec%tol, spec%maxit, spec%tmin, 1, 0, qout, qdout, qddout, iinfo, rinfo, &
                      qsing, dep, redundant, tpass, status, msg)
  if (status < 0) call die(2, where(iinfo(2), msg))
  if (status == MBD_NO_MEMORY) call die(2, trim(msg))
  call write_csv(trim(out_path), iinfo(1))
  if (status == MBD_SINGULAR_CONFIG) then
    call die(3, trim(singular_message()))
  else if (status /= MBD_OK) then
    call die(4, trim(msg) // trim(worst()) // '. ' // trim(rows_written()))
  end if

contains

  !> "FILE:LINE: constraint "NAME": TEXT" for constraint k (TEXT alone for k outside 1..nc).
  function where(k, text) result(s)
    integer, intent(in) :: k
    character(len=*), intent(in) :: text
    character(len=2 * MSG_LEN) :: s
    s = text
    if (k > 0 .and. k <= spec%nc) s = trim(model_path) // ':' // &
      trim(itoa(spec%con_line(k))) // ': constraint "' // trim(spec%con_names(k)) // '": ' // &
      trim(text)
  end function where

  function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=16) :: s
    write (s, '(i0)') i
  end function itoa

  function worst() result(s)
    character(len=MSG_LEN) :: s
    s = ''
    if (iinfo(4) > 0 .and. iinfo(4) <= spec%nc) s = ' ("' // trim(spec%con_names(iinfo(4))) // '")'
  end function worst

  function rows_written() result(s)
    character(len=MSG_LEN) :: s
    write (s, '(a,i0,a,a)') 'Wrote ', iinfo(1), ' rows to ', trim(out_path)
  end function rows_written

  !> One paragraph: when, which driver, which constraints, what to do.
  function singular_message() result(s)
    character(len=4 * MSG_LEN) :: s
    character(len=2 * MSG_LEN) :: names
    character(len=32) :: ts
    integer :: c, r0, nr
    names = ''
    r0 = 1
    do c = 1, spec%nc
      nr = con_nrow(spec%ctab(1, c))
      if (any(dep(r0:r0 + nr - 1) == 1)) names = trim(names) // ' ' // trim(spec%con_names(c))
      r0 = r0 + nr
    end do
    write (ts, '(f0.10)') rinfo(1)
    if (ts(1:1) == '.') ts = '0' // trim(ts)
    if (ts(1:2) == '-.') ts = '-0' // ts(2:)
    s = 'Singular configuration (dead centre) at t = ' // trim(ts) // ' s: '
    if (iinfo(3) > 0 .and. iinfo(3) <= spec%nc) then
      s = trim(s) // ' driver "' // trim(spec%con_names(iinfo(3))) // &
          '" can no longer be met, because the constraints' // trim(names) // &
          ' became dependent (J lost rank).'
    else
      s = trim(s) // ' the constraints' // trim(names) // ' became dependent (J lost rank).'
    end if
    s = trim(s) // ' The mechanism cannot move further as driven; change the driver range or ' // &
        'the link lengths. ' // trim(rows_written()) // '.'
  end function singular_message

  subroutine write_csv(path, nrows)
    character(len=*), intent(in) :: path
    integer, intent(in) :: nrows
    integer :: u, ios, i, b
    character(len=*), parameter :: sfx(9) = [character(len=12) :: '.x', '.y', '.theta', &
      '.x_dot', '.y_dot', '.theta_dot', '.x_ddot', '.y_ddot', '.theta_ddot']
    real(wp) :: t
    open (newunit=u, file=path, status='replace', action='write', iostat=ios)
    if (ios /= 0) call die(2, 'cannot write ' // path)
    write (u, '(a)', advance='no', iostat=ios) 't'
    do b = 1, spec%nb
      do i = 1, 9
        if (ios == 0) write (u, '(a)', advance='no', iostat=ios) ',' // &
          trim(spec%body_names(b)) // trim(sfx(i))
      end do
    end do
    if (ios == 0) write (u, '(a)', iostat=ios) ''
    do k = 1, nrows
      if (ios /= 0) exit
      t = spec%t0 + (spec%t_end - spec%t0) * (real(k - 1, wp) / max(spec%steps, 1))
      if (k == spec%steps + 1) t = spec%t_end
      write (u, '(es24.16e3)', advance='no', iostat=ios) t
      do b = 1, spec%nb
        if (ios == 0) write (u, '(9(",",es24.16e3))', advance='no', iostat=ios) &
          qout(3 * b - 2:3 * b, k), qdout(3 * b - 2:3 * b, k), qddout(3 * b - 2:3 * b, k)
      end do
      if (ios == 0) write (u, '(a)', iostat=ios) ''
    end do
    close (u)
    if (ios /= 0) call die(2, 'cannot write ' // path // ' (disk full?)')
  end subroutine write_csv

  subroutine die(code, text)
    integer, intent(in) :: code
    character(len=*), intent(in) :: text
    write (error_unit, '(a)') 'mbd2d-solve: ' // trim(text)
    select case (code)
    case (2); stop 2, quiet=.true.
    case (3); stop 3, quiet=.true.
    case default; stop 4, quiet=.true.
    end select
  end subroutine die

end program mbd2d_solve
