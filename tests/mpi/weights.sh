#!/bin/sh
# weights.sh SPHC dambreak3d.sph: the particle weights of the decomposition (sphc/mpi/
# decomposition.h, set_weights). In the 3D dam break the water is a block in one corner of a
# tank of walls; split by particle count (SPHC_MPI_UNWEIGHTED=1), 2 ranks cut the tank so that
# one rank holds every fluid particle and the other only walls: the busiest rank's estimated
# work (6 per fluid, 2 per wall particle: the compiler's weights) is 1.21 times the mean at
# dx = 0.08. Weighted, it must be within 10% of the mean (SPHC_MPI_STATS prints each rank's
# counts); unweighted, above (so the check fails without the weights).
set -eu
W=$(mktemp -d "${TMPDIR:-/tmp}/sphc-mpi-w.XXXXXX")
trap 'rm -rf "$W"' EXIT
"$1" "$2" --mpi -o "$W/d3" 2>/dev/null
run() {
  SPHC_MPI_STATS=1 timeout 300 "${SPHC_MPIRUN:-mpirun}" --allow-run-as-root --oversubscribe \
    -np 2 -x SPHC_MPI_STATS "$@" "$W/d3" --set dx=0.08 --max-steps 2 --no-output --quiet \
    2>&1 | grep '^mpi: rank='
}
weighted=$(run)
unweighted=$(SPHC_MPI_UNWEIGHTED=1 run -x SPHC_MPI_UNWEIGHTED)
echo "weighted:"; echo "$weighted"
echo "unweighted:"; echo "$unweighted"
# fluid counts and estimated work (6 per fluid, 2 per wall particle) per rank
check() {
  echo "$1" | sed 's/.*n_boundary=\([0-9]*\) n_fluid=\([0-9]*\).*/\1 \2/' |
    awk -v want="$2" '{ w[NR] = 6 * $2 + 2 * $1; f[NR] = $2; s += w[NR]; if (w[NR] > m) m = w[NR] }
      END { ratio = m / (s / NR); fluidless = (f[1] == 0 || f[2] == 0);
            printf "  fluid per rank %d %d, busiest/mean work %.3f\n", f[1], f[2], ratio;
            if (want == "balanced") exit !(NR == 2 && ratio < 1.1);
            exit !(NR == 2 && fluidless && ratio > 1.1) }'
}
check "$unweighted" fluidless ||
  { echo "weights: expected a rank without fluid and unbalanced work unweighted"; exit 1; }
check "$weighted" balanced || { echo "weights: the weighted split is not balanced"; exit 1; }
echo "weights: ok"
