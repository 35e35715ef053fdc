#!/usr/bin/env bash
# pairtraj: bad deck input (doc/DESIGN.md, doc/PAIRTRAJ_INPUT.md).
# Invariant: every malformed deck stops pairtraj before any work with a non-zero exit status and
# ONE message line on stderr that names the deck file, the namelist group and the variable, and
# no CSV is written. Cases: unknown variable, value out of range, unreadable value, integer
# variable given a real, overlapping start, too many values, unclosed group, unknown group,
# missing file, size ratio out of range or unreadable, a start that overlaps only the larger sphere. Exact text matching
# (no tolerance involved).
set -u
. "$(dirname "$0")/../checks.sh"     # check_result, checks_finish: the verdict shared by shell tests
# the checkout holding this script (tests/run_tests.sh exports FDSUSP_ROOT and FDSUSP_BIN)
root=${FDSUSP_ROOT:-$(cd "$(dirname "$0")/../.." && pwd)}
bin=${FDSUSP_BIN:-$root/bin}/pairtraj
tmp=$(mktemp -d)

check() {  # check NAME DECKFILE GROUP VARIABLE
  local name=$1 deck=$2 group=$3 var=$4 err rc ok=1
  rm -f "$tmp/out.csv"
  "$bin" "$deck" > "$tmp/stdout" 2> "$tmp/stderr"; rc=$?
  err=$(cat "$tmp/stderr")
  [ $rc -ne 0 ] || ok=0
  [ "$(grep -c . "$tmp/stderr")" -eq 1 ] || ok=0
  grep -qF "$deck" "$tmp/stderr" || ok=0
  [ -z "$group" ] || grep -qF "&$group" "$tmp/stderr" || ok=0
  [ -z "$var" ] || grep -qF "variable $var" "$tmp/stderr" || ok=0
  [ ! -e "$tmp/out.csv" ] || ok=0
  check_result $((1 - ok)) "$name (exit $rc): $err"
}

cat > "$tmp/unknown.nml" <<EOF
&pair
  eps_r = 1.0e-2
  epsr_typo = 3
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "unknown variable" "$tmp/unknown.nml" pair epsr_typo

cat > "$tmp/range.nml" <<EOF
&pair
  eps_r = -1.0e-2
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "out of range" "$tmp/range.nml" pair eps_r

cat > "$tmp/badvalue.nml" <<EOF
&pair
  mu_d = 0.3x
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "unreadable value" "$tmp/badvalue.nml" pair mu_d

cat > "$tmp/badint.nml" <<EOF
&integration
  max_steps = 1.5e6
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "integer given a real" "$tmp/badint.nml" integration max_steps

cat > "$tmp/start.nml" <<EOF
&pair
  start = -1.0, 0.5, 0.0
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "overlapping start" "$tmp/start.nml" pair start

cat > "$tmp/unclosed.nml" <<EOF
&output
  csv_file = '$tmp/out.csv'
EOF
check "unclosed group" "$tmp/unclosed.nml" output ""

cat > "$tmp/group.nml" <<EOF
&pairs
  eps_r = 1.0e-2
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "unknown group" "$tmp/group.nml" pairs ""

cat > "$tmp/toomany.nml" <<EOF
&pair
  start = -6.0, 0.5, 0.0, 1.0
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "too many values" "$tmp/toomany.nml" pair start

cat > "$tmp/ratio.nml" <<EOF
&pair
  size_ratio = 0.0
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "size ratio out of range" "$tmp/ratio.nml" pair size_ratio

cat > "$tmp/ratiotext.nml" <<EOF
&pair
  size_ratio = big
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "size ratio unreadable" "$tmp/ratiotext.nml" pair size_ratio

# |start| = 3.2 > 2 + eps_r would do for equal spheres, not for radii 1 and 3
cat > "$tmp/ratiostart.nml" <<EOF
&pair
  size_ratio = 3.0
  start = -3.2, 0.1, 0.0
/
&output
  csv_file = '$tmp/out.csv'
/
EOF
check "start inside the larger sphere" "$tmp/ratiostart.nml" pair start

check "missing file" "$tmp/does_not_exist.nml" "" ""

rm -rf "$tmp"
checks_finish
