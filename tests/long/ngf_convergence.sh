#!/usr/bin/env bash
# `long` test, issue #3 d (Henann 6.1-6.2, Figs. 2a-b and 4a-b): the mesh-convergence study of
# scripts/ngf_convergence.sh for GEOMETRY (column or annulus) with the homogeneous Neumann
# fluidity condition and with g = 0 at the driven wall (reference h/d = 1/900), checked by
# check_convergence.py.
#   GEOMETRY=column|annulus tests/long/ngf_convergence.sh
set -euo pipefail
: "${BUILD_DIR:?Release build directory}" "${SOURCE_DIR:?source directory}" "${GEOMETRY:?column or annulus}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cd "$SOURCE_DIR" # the scripts read cases/ by relative path
scripts/ngf_convergence.sh "$BUILD_DIR" "$out" 900 "$GEOMETRY" >/dev/null
status=0
for bc in neumann dirichlet; do
  echo "== $GEOMETRY, $bc"
  /usr/bin/python3 tests/long/check_convergence.py "ngf-$bc" "$out/convergence_${GEOMETRY}_$bc.csv" ||
    { cat "$out/convergence_${GEOMETRY}_$bc.csv"; status=1; }
done
exit $status
