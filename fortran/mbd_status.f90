!> mbd_status: status codes shared by the whole library.
!!
!! 0 is success, < 0 is bad input (the caller must change the model or the call),
!! > 0 is a numerical failure at a valid input (singular Jacobian, no convergence, ...).
!! Every routine that can fail returns one of these in `status` plus a message.
module mbd_status
  implicit none
  private
  public :: MSG_LEN
  public :: MBD_OK
  public :: MBD_BAD_INPUT, MBD_BAD_BODY, MBD_BAD_PARAM, MBD_BAD_COUNT, MBD_BAD_SETTING
  public :: MBD_SINGULAR, MBD_NO_CONVERGENCE, MBD_SINGULAR_CONFIG, MBD_ASSEMBLY_FAILED
  public :: MBD_LAPACK, MBD_INCONSISTENT, MBD_BRANCH_SWITCH, MBD_INTEGRATOR_FAILED
  public :: MBD_USER_ABORT, MBD_NO_MEMORY

  integer, parameter :: MSG_LEN = 512            !! length of every message string

  integer, parameter :: MBD_OK = 0
  ! bad input (< 0)
  integer, parameter :: MBD_BAD_INPUT = -1       !! malformed table (sizes, kinds)
  integer, parameter :: MBD_BAD_BODY = -2        !! body index out of range, self-joint
  integer, parameter :: MBD_BAD_PARAM = -3       !! non-finite or degenerate parameter
  integer, parameter :: MBD_BAD_COUNT = -4       !! equations and coordinates do not match
  integer, parameter :: MBD_BAD_SETTING = -5     !! analysis settings (steps, tolerance, ...)
  ! numerical failure (> 0)
  integer, parameter :: MBD_SINGULAR = 1         !! singular Jacobian where one was needed
  integer, parameter :: MBD_NO_CONVERGENCE = 2   !! Newton did not converge
  integer, parameter :: MBD_SINGULAR_CONFIG = 3  !! dead centre / toggle reached, located
  integer, parameter :: MBD_ASSEMBLY_FAILED = 4  !! no configuration satisfies Phi(q, t0) = 0
  integer, parameter :: MBD_LAPACK = 5           !! LAPACK reported an illegal argument
  integer, parameter :: MBD_INCONSISTENT = 6     !! redundant constraints that contradict
  integer, parameter :: MBD_BRANCH_SWITCH = 7    !! solution left its assembly branch
  integer, parameter :: MBD_INTEGRATOR_FAILED = 8 !! step size underflow, blow-up
  integer, parameter :: MBD_USER_ABORT = 9       !! a user callback asked to stop
  !> an allocation failed, or would exceed the memory an analysis may use (mbd_memory)
  integer, parameter :: MBD_NO_MEMORY = 10
end module mbd_status
