!> xerbla: LAPACK's error handler, replaced so that the library never stops the process.
!!
!! Reference LAPACK's xerbla prints a message and executes STOP when a routine is called with
!! an illegal argument. Linked into the library, this version returns instead; the LAPACK
!! routine then returns info < 0, which mbd_linsolve's lapack_status turns into the status
!! MBD_LAPACK with a message naming the routine and the argument.
subroutine xerbla(srname, info)
  implicit none
  character(len=*), intent(in) :: srname   !! name of the routine
  integer, intent(in) :: info              !! position of the illegal argument
  if (len(srname) < 0 .or. info < 0) return   ! nothing to do: the caller reports info
end subroutine xerbla
