! summary.json (doc/RHEOLOGY.md): the rheology of a run over its complete blocks,
! as mod_rheology's rheo_summarise computes it, with the block layout, the profiles across y and
! g(theta), and for a mixture its "species" object (doc/RHEOLOGY.md "Per species"), in JSON that
! scripts and the tests read. The numbers carry 17 significant digits, so
! they are the run's doubles; a quantity that is not finite is null. The kernel computes, this
! module writes: the file is the only thing here.
module mod_summary_io
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use mod_kinds, only: dp, pi
  use mod_rheology, only: rheology_t, NSUMMARY, summary_names, species_summary_t, NSPECIES_Q, species_names
  use mod_os_services, only: publish_file
  implicit none
  private
  public :: summary_write

contains

  !> Write the summary of rheo_summarise (value, err, profile, angles over the complete blocks, the
  !> last of them ending at last_step) to path as JSON (rank 0 only). info: 0 ok, else an iostat or errno.
  !> species (a mixture's, rheo_summarise_species): its "species" object after "pair_distribution".
  subroutine summary_write(r, path, last_step, complete, value, err, profile, angles, info, species)
    type(rheology_t), intent(in) :: r
    character(len=*), intent(in) :: path
    integer, intent(in) :: last_step, complete
    real(dp), intent(in) :: value(NSUMMARY), err(NSUMMARY), profile(:, :), angles(:, :)
    integer, intent(out) :: info
    type(species_summary_t), intent(in), optional :: species
    integer :: u, k
    real(dp), allocatable :: y(:), theta(:)
    allocate(y(r%nbins), theta(r%nangles))
    do k = 1, r%nbins
      y(k) = (k - 0.5_dp) * r%box(2) / r%nbins
    end do
    do k = 1, r%nangles
      theta(k) = (k - 0.5_dp) * 2 * pi / r%nangles
    end do
    ! written to path.tmp (every statement checked: a full disk jumps to 90) and renamed
    open(newunit=u, file=trim(path)//'.tmp', status='replace', action='write', iostat=info)
    if (info /= 0) return
    write(u, '(a)', err=90) '{'
    write(u, '(a)', err=90) '  "program": "fdsusp",'
    write(u, '(a,a,a)', err=90) '  "complete": ', trim(merge('true ', 'false', complete == r%blocks)), ','
    write(u, '(a,i0,a,i0,a)', err=90) '  "blocks": ', r%blocks, ', "blocks_complete": ', complete, ','
    write(u, '(a,i0,a,i0,a,i0,a)', err=90) '  "discard_step": ', r%discard_step, ', "block_steps": ', r%block_steps, &
         ', "last_step": ', last_step, ','
    write(u, '(a,a,a)', err=90) '  "records_per_block": ', trim(json_array(r%block_records(1:max(1, complete)))), ','
    write(u, '(a,2(a,a),a)', err=90) '  "core": ', trim(json_array(r%core)), ', "shear_rate": ', trim(json_number(r%shear_rate)), ','
    ! a rate that varies (&shear protocol): the quantities are stresses over eta*|shear_rate|
    if (r%raw_stress) write(u, '(a)', err=90) '  "stresses_over_reference_rate": true,'
    write(u, '(a)', err=90) '  "quantities": {'
    do k = 1, NSUMMARY
      write(u, '(5a)', err=90) '    "', trim(summary_names(k)), '": {"value": ', trim(json_number(value(k))), &
           ', "error": '//trim(json_number(err(k)))//'}'//trim(merge(', ', '  ', k < NSUMMARY))
    end do
    write(u, '(a)', err=90) '  },'
    write(u, '(a)', err=90) '  "profiles": {'
    write(u, '(a,a,a)', err=90) '    "y": ', json_array(y), ','
    write(u, '(a,a,a)', err=90) '    "solid_fraction": ', json_array(profile(:, 1)), ','
    write(u, '(a,a)', err=90) '    "velocity": ', json_array(profile(:, 2))
    write(u, '(a)', err=90) '  },'
    write(u, '(a)', err=90) '  "pair_distribution": {'
    write(u, '(a,a,a,a,a)', err=90) '    "r_outer": ', trim(json_number(r%r_outer)), ', "r_contact": ', &
         trim(json_number(r%r_contact)), ','
    write(u, '(a,a,a)', err=90) '    "theta": ', json_array(theta), ','
    write(u, '(a,a,a)', err=90) '    "g": ', json_array(angles(:, 1)), ','
    write(u, '(a,a)', err=90) '    "g_contact": ', json_array(angles(:, 2))
    if (present(species)) then
      write(u, '(a)', err=90) '  },'
      call write_species(u, r, species, info)
      if (info /= 0) go to 90
    else
      write(u, '(a)', err=90) '  }'
    end if
    write(u, '(a)', err=90) '}'
    flush(u, iostat=info)
    close(u, iostat=k)
    if (info == 0) info = k
    if (info == 0) info = publish_file(trim(path)//'.tmp', path)
    return
90  info = 1
    close(u, iostat=k)
  end subroutine summary_write

  ! A mixture's "species" object (doc/RHEOLOGY.md "Per species"): radius and count of each species,
  ! the per-species quantities (value and error: one entry per species), the profiles phi_s(y) with
  ! their errors and n_s(y) (one array per species), and g_ab(r) with its errors as g[a][b] (a the
  ! reference's species). info: 0 ok, 1 a write failed.
  subroutine write_species(u, r, ss, info)
    integer, intent(in) :: u
    type(rheology_t), intent(in) :: r
    type(species_summary_t), intent(in) :: ss
    integer, intent(out) :: info
    integer :: k
    info = 1
    write(u, '(a)', err=90) '  "species": {'
    write(u, '(a,a,a)', err=90) '    "radius": ', json_array(r%species_radius / r%radius), ','
    write(u, '(a,a,a)', err=90) '    "count": ', json_array(r%species_count), ','
    write(u, '(a)', err=90) '    "quantities": {'
    do k = 1, NSPECIES_Q
      write(u, '(5a)', err=90) '      "', trim(species_names(k)), '": {"value": ', json_array(ss%value(k, :)), &
           ', "error": '//json_array(ss%error(k, :))//'}'//trim(merge(', ', '  ', k < NSPECIES_Q))
    end do
    write(u, '(a)', err=90) '    },'
    write(u, '(a)', err=90) '    "profiles": {'
    write(u, '(a,a,a)', err=90) '      "solid_fraction": ', json_matrix(ss%phi), ','
    write(u, '(a,a,a)', err=90) '      "solid_fraction_error": ', json_matrix(ss%phi_error), ','
    write(u, '(a,a)', err=90) '      "number_density": ', json_matrix(ss%number)
    write(u, '(a)', err=90) '    },'
    write(u, '(a)', err=90) '    "pair_distribution": {'
    write(u, '(a,a,a)', err=90) '      "radial_width": ', trim(json_number(r%radial_width / r%radius)), ','
    write(u, '(a,a,a)', err=90) '      "r": ', json_array(ss%r), ','
    write(u, '(a,a,a)', err=90) '      "g": ', json_tensor(ss%g), ','
    write(u, '(a,a)', err=90) '      "g_error": ', json_tensor(ss%g_error)
    write(u, '(a)', err=90) '    }'
    write(u, '(a)', err=90) '  }'
    info = 0
90  return
  end subroutine write_species

  ! [x(:, 1), x(:, 2), ...] as nested JSON arrays.
  function json_matrix(x) result(s)
    real(dp), intent(in) :: x(:, :)
    character(len=:), allocatable :: s
    integer :: k
    s = '['
    do k = 1, size(x, 2)
      s = s//json_array(x(:, k))
      if (k < size(x, 2)) s = s//', '
    end do
    s = s//']'
  end function json_matrix

  ! [[x(:, 1, 1), x(:, 2, 1), ...], [x(:, 1, 2), ...], ...]: x(:, b, a) is entry [a][b].
  function json_tensor(x) result(s)
    real(dp), intent(in) :: x(:, :, :)
    character(len=:), allocatable :: s
    integer :: k
    s = '['
    do k = 1, size(x, 3)
      s = s//json_matrix(x(:, :, k))
      if (k < size(x, 3)) s = s//', '
    end do
    s = s//']'
  end function json_tensor

  !> A number in JSON: 17 significant digits, null when not finite.
  function json_number(x) result(s)
    real(dp), intent(in) :: x
    character(len=32) :: s
    if (.not. ieee_is_finite(x)) then
      s = 'null'
    else
      write(s, '(es25.16e3)') x
      s = adjustl(s)
    end if
  end function json_number

  function json_array(x) result(s)
    real(dp), intent(in) :: x(:)
    character(len=:), allocatable :: s
    integer :: k
    s = '['
    do k = 1, size(x)
      s = s//trim(json_number(x(k)))
      if (k < size(x)) s = s//', '
    end do
    s = s//']'
  end function json_array

end module mod_summary_io
