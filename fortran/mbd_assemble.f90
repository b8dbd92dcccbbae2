!> mbd_assemble: stack every constraint's rows into Phi, J, nu and gamma.
!!
!! Phi(q, t) = [Phi^K(q); Phi^D(q, t)],  J = Phi_q,  nu = -Phi_t,
!! gamma = -(J q_dot)_q q_dot - 2 Phi_qt q_dot - Phi_tt.
!! Each constraint writes its rows into slices of phi, nu, gam and its local Jacobian block
!! into jb(:, :, k); scatter_dense then places the blocks in a dense J. No allocation here.
module mbd_assemble
  use mbd_kinds, only: wp, zero
  use mbd_points, only: NLOC, MAXROW
  use mbd_model, only: model_t, model_slots
  use mbd_constraints, only: con_eval, con_init_extra
  implicit none
  private
  public :: assemble_blocks, scatter_dense, assemble_dense, init_extras, gather_local

contains

  !> Local coordinates (and velocities) of constraint k.
  pure subroutine gather_local(m, k, q, ql)
    type(model_t), intent(in) :: m       !! model
    integer, intent(in) :: k             !! constraint
    real(wp), intent(in) :: q(:)         !! global vector
    real(wp), intent(out) :: ql(NLOC)    !! local vector
    integer :: s
    do s = 1, NLOC
      if (m%loc(s, k) > 0) then
        ql(s) = q(m%loc(s, k))
      else
        ql(s) = zero
      end if
    end do
  end subroutine gather_local

  !> Phi, nu, gamma and the local Jacobian blocks at (q, q_dot, t).
  pure subroutine assemble_blocks(m, q, qd, t, phi, nu, gam, jb)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:)              !! coordinates (nq)
    real(wp), intent(in) :: qd(:)             !! velocities (nq), for gamma
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: phi(:)           !! Phi (neq)
    real(wp), intent(out) :: nu(:)            !! nu (neq)
    real(wp), intent(out) :: gam(:)           !! gamma (neq)
    real(wp), intent(out) :: jb(:, :, :)      !! local blocks (MAXROW, NLOC, nc)
    real(wp) :: ql(NLOC), qdl(NLOC)
    integer :: k, r0, r1, si, sj
    do k = 1, m%nc
      call gather_local(m, k, q, ql)
      call gather_local(m, k, qd, qdl)
      call model_slots(m, k, si, sj)
      r0 = m%row0(k); r1 = r0 + m%nrow(k) - 1
      jb(:, :, k) = zero
      call con_eval(m%kind(k), m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                    si, sj, ql, qdl, t, phi(r0:r1), jb(1:m%nrow(k), :, k), nu(r0:r1), gam(r0:r1))
    end do
  end subroutine assemble_blocks

  !> Place the local blocks into a dense J (neq x nq).
  pure subroutine scatter_dense(m, jb, jac)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: jb(:, :, :)       !! local blocks
    real(wp), intent(out) :: jac(:, :)        !! dense Jacobian
    integer :: k, s, r, c
    jac = zero
    do k = 1, m%nc
      do s = 1, NLOC
        c = m%loc(s, k)
        if (c == 0) cycle
        do r = 1, m%nrow(k)
          jac(m%row0(k) + r - 1, c) = jac(m%row0(k) + r - 1, c) + jb(r, s, k)
        end do
      end do
    end do
  end subroutine scatter_dense

  !> Phi, nu, gamma and the dense J in one call.
  pure subroutine assemble_dense(m, q, qd, t, phi, nu, gam, jb, jac)
    type(model_t), intent(in) :: m            !! model
    real(wp), intent(in) :: q(:), qd(:)       !! coordinates and velocities
    real(wp), intent(in) :: t                 !! time
    real(wp), intent(out) :: phi(:), nu(:), gam(:)  !! Phi, nu, gamma
    real(wp), intent(out) :: jb(:, :, :)      !! work: local blocks
    real(wp), intent(out) :: jac(:, :)        !! dense Jacobian
    call assemble_blocks(m, q, qd, t, phi, nu, gam, jb)
    call scatter_dense(m, jb, jac)
  end subroutine assemble_dense

  !> Starting values of the extra coordinates (cam contact parameters) from the bodies in q.
  pure subroutine init_extras(m, q)
    type(model_t), intent(in) :: m      !! model
    real(wp), intent(inout) :: q(:)     !! coordinates; extras are overwritten
    real(wp) :: ql(NLOC)
    integer :: k, si, sj
    do k = 1, m%nc
      if (m%loc(NLOC, k) == 0) cycle
      call gather_local(m, k, q, ql)
      call model_slots(m, k, si, sj)
      call con_init_extra(m%kind(k), m%suba(k), m%subb(k), m%p(m%po(k):m%po(k) + m%pn(k) - 1), &
                          si, sj, ql)
      q(m%loc(NLOC, k)) = ql(NLOC)
    end do
  end subroutine init_extras

end module mbd_assemble
