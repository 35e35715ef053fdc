program fdsusp
  implicit none
end program fdsusp
