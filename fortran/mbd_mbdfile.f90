!> mbd_mbdfile: read the plain-text model file written by `mbd2d export`.
!!
!! Format 1 (whitespace separated; '#' starts a comment line; names have no spaces):
!!   mbd2d 1
!!   name <model name>
!!   analysis kinematics
!!   t0 <time>   t_end <time>   steps <n>   tol <x>   maxit <n>   tmin <x>   (one per line)
!!   bodies <nb>
!!   <name> <x0> <y0> <theta0>                       (nb lines)
!!   constraints <nc>
!!   <name> <kind> <body i> <body j> <sub a> <sub b> <offset> <length>   (nc lines)
!!   params <np>
!!   <np reals, any number per line, no comments inside this block>
!!   end
!! The constraint columns are the flat table of mbd_model; tol, maxit, tmin <= 0 mean default.
module mbd_mbdfile
  use mbd_kinds, only: wp, zero
  use mbd_status, only: MBD_OK, MBD_BAD_INPUT, MSG_LEN
  use mbd_model, only: NCT
  implicit none
  private
  public :: NAME_LEN, mbd_spec_t, mbd_read

  integer, parameter :: NAME_LEN = 64   !! longest body or constraint name

  !> The contents of a model file.
  type :: mbd_spec_t
    character(len=NAME_LEN) :: name = ''
    character(len=NAME_LEN) :: analysis = 'kinematics'
    real(wp) :: t0 = zero, t_end = zero, tol = zero, tmin = zero
    integer :: steps = 0, maxit = 0, nb = 0, nc = 0
    character(len=NAME_LEN), allocatable :: body_names(:), con_names(:)
    real(wp), allocatable :: q0(:, :)     !! (3, nb)
    integer, allocatable :: ctab(:, :)    !! (NCT, nc)
    real(wp), allocatable :: rpar(:)
  end type mbd_spec_t

contains

  !> Read a model file.
  subroutine mbd_read(path, spec, status, msg)
    character(len=*), intent(in) :: path        !! file to read
    type(mbd_spec_t), intent(out) :: spec       !! contents
    integer, intent(out) :: status              !! MBD_OK or MBD_BAD_INPUT
    character(len=MSG_LEN), intent(out) :: msg  !! what is wrong
    integer :: u, ios, lineno, i, n, version
    character(len=4096) :: line
    character(len=NAME_LEN) :: key
    logical :: have_header, done
    status = MBD_OK; msg = ''
    open (newunit=u, file=path, status='old', action='read', iostat=ios)
    if (ios /= 0) then
      status = MBD_BAD_INPUT; msg = 'cannot open model file ' // trim(path); return
    end if
    lineno = 0; have_header = .false.; done = .false.
    allocate (spec%body_names(0), spec%con_names(0), spec%q0(3, 0), spec%ctab(NCT, 0), &
              spec%rpar(0))
    do
      call next_line(ios)
      if (ios /= 0) exit
      read (line, *, iostat=ios) key
      if (ios /= 0) call fail('cannot read a keyword')
      if (status /= MBD_OK) exit
      if (.not. have_header .and. key /= 'mbd2d') then
        call fail('not an mbd2d model file (first line must be "mbd2d 1")'); exit
      end if
      select case (key)
      case ('mbd2d')
        read (line, *, iostat=ios) key, version
        if (ios /= 0 .or. version /= 1) call fail('unsupported format version')
        have_header = .true.
      case ('name')
        read (line, *, iostat=ios) key, spec%name
      case ('analysis')
        read (line, *, iostat=ios) key, spec%analysis
      case ('t0')
        read (line, *, iostat=ios) key, spec%t0
      case ('t_end')
        read (line, *, iostat=ios) key, spec%t_end
      case ('steps')
        read (line, *, iostat=ios) key, spec%steps
      case ('tol')
        read (line, *, iostat=ios) key, spec%tol
      case ('maxit')
        read (line, *, iostat=ios) key, spec%maxit
      case ('tmin')
        read (line, *, iostat=ios) key, spec%tmin
      case ('bodies')
        read (line, *, iostat=ios) key, n
        if (ios /= 0 .or. n < 0) then
          call fail('bad body count'); exit
        end if
        spec%nb = n
        deallocate (spec%body_names, spec%q0)
        allocate (spec%body_names(n), spec%q0(3, n))
        do i = 1, n
          call next_line(ios)
          if (ios == 0) read (line, *, iostat=ios) spec%body_names(i), spec%q0(:, i)
          if (ios /= 0) then
            call fail('bad body line'); exit
          end if
        end do
      case ('constraints')
        read (line, *, iostat=ios) key, n
        if (ios /= 0 .or. n < 0) then
          call fail('bad constraint count'); exit
        end if
        spec%nc = n
        deallocate (spec%con_names, spec%ctab)
        allocate (spec%con_names(n), spec%ctab(NCT, n))
        spec%ctab = 0
        do i = 1, n
          call next_line(ios)
          if (ios == 0) read (line, *, iostat=ios) spec%con_names(i), spec%ctab(1:7, i)
          if (ios /= 0) then
            call fail('bad constraint line'); exit
          end if
        end do
      case ('params')
        read (line, *, iostat=ios) key, n
        if (ios /= 0 .or. n < 0) then
          call fail('bad parameter count'); exit
        end if
        deallocate (spec%rpar)
        allocate (spec%rpar(n))
        if (n > 0) read (u, *, iostat=ios) spec%rpar
        if (ios /= 0) call fail('cannot read the parameters')
      case ('end')
        done = .true.
      case default
        call fail('unknown keyword "' // trim(key) // '"')
      end select
      if (status /= MBD_OK .or. done) exit
      if (ios /= 0) then
        call fail('cannot read the value of "' // trim(key) // '"'); exit
      end if
    end do
    close (u)
    if (status == MBD_OK .and. .not. done) then
      status = MBD_BAD_INPUT; msg = trim(path) // ': missing "end" line (file truncated?)'
    end if
  contains
    subroutine next_line(iostat)
      integer, intent(out) :: iostat
      do
        read (u, '(a)', iostat=iostat) line
        if (iostat /= 0) return
        lineno = lineno + 1
        line = adjustl(line)
        if (len_trim(line) > 0 .and. line(1:1) /= '#') return
      end do
    end subroutine next_line
    subroutine fail(what)
      character(len=*), intent(in) :: what
      status = MBD_BAD_INPUT
      write (msg, '(a,a,i0,a,a)') trim(path), ':', lineno, ': ', what
    end subroutine fail
  end subroutine mbd_read

end module mbd_mbdfile
