!> mbd_memory: how much memory an analysis may ask for, and the MBD_NO_MEMORY messages.
!!
!! Every allocation in the library has stat=; a failed one becomes MBD_NO_MEMORY with a
!! message giving the size asked and what to change (mem_fail). Large requests are checked
!! first against what the machine can give (mem_check): on Linux an allocation larger than
!! the free memory may succeed and the process is killed later, when the pages are touched.
!!   limit = min(MemTotal / 2, MemAvailable)        (/proc/meminfo; no limit where unknown)
!! Half the physical memory is the rule the Python front end applies to its output arrays.
!! Requests below CHECK_ABOVE are not checked (no file read in small or per-step calls).
module mbd_memory
  use mbd_kinds, only: wp, half, zero
  use mbd_status, only: MBD_OK, MBD_NO_MEMORY, MSG_LEN
  implicit none
  private
  public :: MIB, GIB, CHECK_ABOVE, REAL_BYTES, mem_limit, mem_text, mem_check, mem_fail, &
            zero_fill, mem_grow

  real(wp), parameter :: MIB = 1048576.0_wp            !! bytes in a MiB
  real(wp), parameter :: GIB = 1073741824.0_wp         !! bytes in a GiB
  real(wp), parameter :: CHECK_ABOVE = 64 * MIB        !! smaller requests are not checked
  real(wp), parameter :: REAL_BYTES = 8.0_wp           !! bytes of a real(wp)

contains

  !> Bytes one analysis may ask for: min(MemTotal / 2, MemAvailable) from /proc/meminfo,
  !! huge() where the file cannot be read (the allocations' stat= still guards).
  real(wp) function mem_limit() result(lim)
    integer :: u, ios, ios2
    character(len=256) :: line
    real(wp) :: kb, total, avail
    lim = huge(lim)
    total = -1; avail = -1
    open (newunit=u, file='/proc/meminfo', status='old', action='read', iostat=ios)
    if (ios /= 0) return
    do
      read (u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (line(1:9) == 'MemTotal:') then
        read (line(10:), *, iostat=ios2) kb
        if (ios2 == 0) total = 1024 * kb
      else if (line(1:13) == 'MemAvailable:') then
        read (line(14:), *, iostat=ios2) kb
        if (ios2 == 0) avail = 1024 * kb
      end if
    end do
    close (u)
    if (total > 0) lim = half * total
    if (avail > 0) lim = min(lim, avail)
  end function mem_limit

  !> A byte count as text: "512.0 MiB", "26.8 GiB".
  pure function mem_text(bytes) result(s)
    real(wp), intent(in) :: bytes   !! bytes
    character(len=24) :: s
    if (.not. (bytes < 1.0e6_wp * GIB)) then
      write (s, '(es10.3,a)') bytes / GIB, ' GiB'
    else if (bytes >= GIB) then
      write (s, '(f12.1,a)') bytes / GIB, ' GiB'
    else
      write (s, '(f12.1,a)') bytes / MIB, ' MiB'
    end if
    s = adjustl(s)
  end function mem_text

  !> MBD_NO_MEMORY when a request of `bytes` exceeds mem_limit (only requests above
  !! CHECK_ABOVE are checked). msg is written only on a failure.
  subroutine mem_check(bytes, what, hint, status, msg)
    real(wp), intent(in) :: bytes                  !! size of the request
    character(len=*), intent(in) :: what           !! what it is for
    character(len=*), intent(in) :: hint           !! what to change
    integer, intent(out) :: status                 !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation (on a failure)
    real(wp) :: lim
    status = MBD_OK
    if (bytes <= CHECK_ABOVE) return
    lim = mem_limit()
    if (bytes <= lim) return
    status = MBD_NO_MEMORY
    msg = 'not enough memory: ' // what // ' would need ' // trim(mem_text(bytes)) // &
          ', more than the ' // trim(mem_text(lim)) // ' one analysis may use on this ' // &
          'machine (half its memory, at most what is free); ' // hint
  end subroutine mem_check

  !> MBD_NO_MEMORY and its message after a failed allocation of about `bytes`.
  pure subroutine mem_fail(bytes, what, hint, status, msg)
    real(wp), intent(in) :: bytes                  !! size of the request
    character(len=*), intent(in) :: what           !! what it was for
    character(len=*), intent(in) :: hint           !! what to change
    integer, intent(out) :: status                 !! MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg   !! explanation
    status = MBD_NO_MEMORY
    msg = 'not enough memory: allocating ' // trim(mem_text(bytes)) // ' for ' // what // &
          ' failed; ' // hint
  end subroutine mem_fail

  !> A workspace of at least lw entries (a LAPACK query's answer): work grows when it is
  !! smaller; MBD_NO_MEMORY (work then of one entry) when it cannot.
  subroutine mem_grow(work, lw, what, hint, status, msg)
    real(wp), allocatable, intent(inout) :: work(:)  !! the workspace (allocated)
    integer, intent(in) :: lw                        !! entries needed
    character(len=*), intent(in) :: what, hint       !! for the message
    integer, intent(out) :: status                   !! MBD_OK or MBD_NO_MEMORY
    character(len=MSG_LEN), intent(inout) :: msg     !! explanation
    integer :: ierr
    status = MBD_OK
    if (size(work) >= lw) return
    deallocate (work)
    allocate (work(lw), stat=ierr)
    if (ierr /= 0) then
      call mem_fail(REAL_BYTES * lw, what, hint, status, msg)
      allocate (work(1), stat=ierr)
    end if
  end subroutine mem_grow

  !> a(1:n) = 0 for an array seen flat: one memset (gfortran clears a 2-D or 3-D array or
  !! section column by column, a memset call per column).
  pure subroutine zero_fill(n, a)
    integer, intent(in) :: n          !! number of entries
    real(wp), intent(out) :: a(n)     !! the array, flat
    a = zero
  end subroutine zero_fill

end module mbd_memory
