#!/usr/bin/env bash
# sylva render --mpi overhead: one process with 2 threads against mpirun -np 2 with 1 thread per rank on the
# default forest (896x448, warm cache), REPS runs of each alternating, the two pictures compared each time.
#   tests/bench/bench_mpi_overhead.sh BUILD_DIR [REPS]      (docs/PERFORMANCE.md "MPI rendering")
set -euo pipefail
S="${1:?usage: $0 BUILD_DIR [REPS]}/pipeline/sylva"
REPS="${2:-3}"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none
ROOT=()
if [[ $(id -u) -eq 0 ]]; then ROOT=(--allow-run-as-root); fi
"$S" render --quiet -o "$OUT/warm.png" >/dev/null   # grow and light the species once (cache)
trace() { sed -n 's/^time: .*trace \([0-9.]*\) s$/\1/p'; }
single=() mpi=() wall1=() wall2=()
for ((i = 0; i < REPS; ++i)); do
  t0=$(date +%s.%N); s=$("$S" render --threads 2 --stats --quiet -o "$OUT/s.png" | trace); t1=$(date +%s.%N)
  m=$(mpirun "${ROOT[@]}" --oversubscribe --bind-to none -np 2 "$S" render --mpi --threads 1 --stats --quiet -o "$OUT/m.png" | trace)
  t2=$(date +%s.%N)
  cmp -s "$OUT/s.png" "$OUT/m.png" || { echo "the pictures differ" >&2; exit 1; }
  single+=("$s") mpi+=("$m") wall1+=("$(echo "$t1 - $t0" | bc)") wall2+=("$(echo "$t2 - $t1" | bc)")
  echo "run $i: single trace $s s wall ${wall1[-1]} s; 2 ranks trace $m s wall ${wall2[-1]} s"
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
ms=$(median "${single[@]}") mm=$(median "${mpi[@]}") w1=$(median "${wall1[@]}") w2=$(median "${wall2[@]}")
echo "single_trace_s=$ms"
echo "mpi2_trace_s=$mm"
echo "single_wall_s=$w1"
echo "mpi2_wall_s=$w2"
echo "trace_ratio=$(echo "scale=3; $mm / $ms" | bc)"
echo "wall_ratio=$(echo "scale=3; $w2 / $w1" | bc)"
