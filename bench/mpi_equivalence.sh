#!/bin/sh
# The distributed reduction against the serial one at scale: a chain of
# N = 2 n states with an on-site cosh potential (tests/mpi/test_mpi_nl.c
# --scale n, default n = 100000: N = 2e5), 101 snapshots, r = 20:
# GMG-POD with ECSW and SP1 with ECSW at P = 1, 2, 3, 4 ranks (2, 3: uneven
# blocks; 4: rank 2 owns no rows), each against the serial phgmg_reduce run
# on rank 0 of the same job. Printed per P: the raw snapshots' sigma_r /
# sigma_1, the POD's singular values, V^T (J - R) V from the TSQR POD and from
# a Gram-matrix POD (the negative control: it must miss), the serial model's
# own movement under one-ulp changes of the snapshots, and K, Qh, the ECSW
# points and weights, V0's rows at the points and 200 steps of outputs
# against the serial model. Then GMG-QM (POD and greedy manifolds, r = 8,
# rn = 3, no terms: the linear chain of n masses, 81 snapshots) against the
# serial GMG-QM: the basis [B, V1], every block, q_max, 100 steps of
# outputs. QM_ONLY=1: only the GMG-QM comparison; QM_COSH=1: only GMG-QM,
# on the linear chain and then on the cosh chain with ECSW (r = 8, rn = 4,
# the POD and greedy manifolds; from 4096 live terms the screened fit;
# stepped at 0.001: these reduced models are stiff),
# also against the serial ECSW points and weights.
#   sh bench/mpi_equivalence.sh [n] [P ...]      (log: build/mpi_equivalence.txt)
set -e
n=${1:-100000}
[ $# -gt 0 ] && shift
PS=${*:-1 2 3 4}
MPICC=${MPICC:-mpicc}
if [ -z "$MPIRUN" ]; then
  MPIRUN="mpirun --oversubscribe"
  [ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
mkdir -p build
$MPICC -O2 -std=c99 -DPHGMG_IMPLEMENTATION -o build/test_mpi_nl_scale tests/mpi/test_mpi_nl.c -lm
: > build/mpi_equivalence.txt
for p in $PS; do
  /usr/bin/time -f "P = $p: %e s wall, %M KB peak (largest rank)" $MPIRUN -np "$p" ./build/test_mpi_nl_scale \
      "$([ -n "$QM_COSH" ] && echo --scale-qm-cosh || { [ -n "$QM_ONLY" ] && echo --scale-qm || echo --scale; })" "$n" 2>&1 \
    | grep -v '^--\|^$\|Primary job\|non-zero exit\|mpirun detected\|Process name\|Exit code\|aborted\|thus causing\|terminated' \
    | tee -a build/mpi_equivalence.txt
done
