# Used by driver/physics-drift.sph: compares two files of comma-separated numbers (h5dump -y -w 0
# -o ...) value by value: each value of the second file must be the first's + shift, to 1e-12.
# Prints "compared N values, worst error E, ok" (or "FAIL" with the first bad value).
BEGIN { RS = "[ \t\n]*,[ \t\n]*|[ \t\n]+"; n0 = 0; n1 = 0; bad = 0; worst = 0 }
$0 == "" { next }
FNR == NR { before[n0++] = $0 + 0; next }
{
  err = $0 - (before[n1] + shift); if (err < 0) err = -err
  if (err > worst) worst = err
  if (err > 1e-12 && !bad) { bad = 1; first = sprintf("value %d: %.17g, expected %.17g", n1, $0, before[n1] + shift) }
  n1++
}
END {
  if (n0 != n1) { printf "FAIL: %d values before, %d after\n", n0, n1; exit 1 }
  if (bad) { printf "FAIL: %s\n", first; exit 1 }
  printf "compared %d values, worst error %g, ok\n", n1, worst
}
