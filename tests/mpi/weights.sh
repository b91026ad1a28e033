#!/bin/sh
# weights.sh SPHC dambreak3d.sph: the particle weights of the decomposition (sphc/mpi/
# decomposition.h). In the 3D dam break the water is a block in one corner of a tank of walls.
# Every run counts its work (SPHC_MPI_STATS prints each rank's `work=`: per particle of the
# rank, the candidates it tested and its neighbour pairs x loops in the passes, plus a cost per
# particle, at fixed costs in about instructions; integers, independent of the machine's
# load), 2 ranks at dx = 0.08, 6 steps:
#   - unweighted (SPHC_MPI_UNWEIGHTED=1): split by particle count, one rank holds every fluid
#     particle and the other only walls; the busiest rank's counted work is 1.68 times the
#     mean;
#   - the compiler's estimate (SPHC_MPI_WEIGHTS=estimated: 6 per fluid, 2 per wall particle):
#     the estimated work is balanced within 10% (as before), but the counted work is 1.52
#     times the mean: a fluid particle does ~10 times a wall's work, not 3 times;
#   - measured weights (the default): after the first evaluation the ranks re-cut with each
#     particle's counted work; the counted work of the last evaluation must be within 10% of
#     the mean (measured 1.02), and the estimate's above it (so the check fails with the old
#     weights). The counts are deterministic, so these ratios are the same on every run.
set -eu
W=$(mktemp -d "${TMPDIR:-/tmp}/sphc-mpi-w.XXXXXX")
trap 'rm -rf "$W"' EXIT
"$1" "$2" --mpi -o "$W/d3" 2>/dev/null
run() {
  SPHC_MPI_STATS=1 timeout 300 "${SPHC_MPIRUN:-mpirun}" --allow-run-as-root --oversubscribe \
    -np 2 -x SPHC_MPI_STATS "$@" "$W/d3" --set dx=0.08 --max-steps 6 --no-output --quiet \
    2>&1 | grep '^mpi: rank='
}
measured=$(run)
estimated=$(SPHC_MPI_WEIGHTS=estimated run -x SPHC_MPI_WEIGHTS)
unweighted=$(SPHC_MPI_UNWEIGHTED=1 run -x SPHC_MPI_UNWEIGHTED)
echo "measured:"; echo "$measured"
echo "estimated:"; echo "$estimated"
echo "unweighted:"; echo "$unweighted"
# Per rank: walls, fluid, counted work. Prints the fluid per rank, the busiest rank's
# estimated (6 per fluid, 2 per wall particle) and counted work over the mean, then judges:
#   fluidless: a rank without fluid, both ratios above 1.1;
#   estimate:  estimated work within 1.1, counted work above 1.1;
#   balanced:  counted work within 1.1.
check() {
  echo "$1" |
    sed 's/.*n_boundary=\([0-9]*\) n_fluid=\([0-9]*\).* work=\([0-9]*\).*/\1 \2 \3/' |
    awk -v want="$2" '{ e[NR] = 6 * $2 + 2 * $1; f[NR] = $2; c[NR] = $3; se += e[NR]; sc += c[NR];
                        if (e[NR] > me) me = e[NR]; if (c[NR] > mc) mc = c[NR] }
      END { re = me / (se / NR); rc = mc / (sc / NR); fluidless = (f[1] == 0 || f[2] == 0);
            printf "  %s: fluid per rank %d %d, busiest/mean estimated work %.3f, counted work %.3f\n",
                   want, f[1], f[2], re, rc;
            if (NR != 2) exit 1;
            if (want == "fluidless") exit !(fluidless && re > 1.1 && rc > 1.1);
            if (want == "estimate") exit !(re < 1.1 && rc > 1.1);
            exit !(rc < 1.1) }'
}
check "$unweighted" fluidless ||
  { echo "weights: expected a rank without fluid and unbalanced work unweighted"; exit 1; }
check "$estimated" estimate ||
  { echo "weights: expected the estimate balanced in its own weights, not in counted work"; exit 1; }
check "$measured" balanced || { echo "weights: the measured weights do not balance the work"; exit 1; }
echo "$measured" | grep -q 'weights=measured' || { echo "weights: not the measured mode"; exit 1; }
echo "weights: ok"
