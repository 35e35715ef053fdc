# The verdict of a shell test (bash), the counterpart of tests/checks.py: source it, record each
# check with check_result, end with checks_finish.
#   . "$(dirname "$0")/../checks.sh"
#   check_result STATUS MESSAGE   one check: STATUS 0 holds ('ok    MESSAGE'), else 'FAIL  MESSAGE'
#   checks_finish                 exit 1 unless at least one check was made and none failed
# A test that exits without checks_finish gets the same verdict (an EXIT trap): made no check or a
# failed one, and its status is forced to 1.
CHECKS_MADE=0
CHECKS_FAILED=0
_CHECKS_FINISHED=0

check_result() {
  CHECKS_MADE=$((CHECKS_MADE + 1))
  if [ "$1" -eq 0 ]; then
    echo "ok    $2"
  else
    echo "FAIL  $2"
    CHECKS_FAILED=$((CHECKS_FAILED + 1))
  fi
}

_checks_verdict() {   # prints the reason the test fails, if it does
  if [ "$CHECKS_FAILED" -gt 0 ]; then echo "$CHECKS_FAILED check(s) failed"
  elif [ "$CHECKS_MADE" -eq 0 ]; then echo "the test made no checks"
  fi
}

checks_finish() {
  local why
  _CHECKS_FINISHED=1
  why=$(_checks_verdict)
  if [ -n "$why" ]; then echo "$why"; exit 1; fi
  echo "all $CHECKS_MADE checks passed"
  exit 0
}

_checks_at_exit() {
  local status=$? why
  [ "$_CHECKS_FINISHED" -eq 1 ] && exit "$status"
  why=$(_checks_verdict)
  if [ -n "$why" ]; then echo "$why (the test ended without checks_finish)"; exit 1; fi
  exit "$status"
}
trap _checks_at_exit EXIT
