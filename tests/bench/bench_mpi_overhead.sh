#!/usr/bin/env bash
# sylva render --mpi overhead: one process with 2 threads against mpirun -np 2 with 1 thread per rank on the
# default forest (896x448, warm cache), the scene broadcast by rank 0 (default) and built by every rank
# (--mpi-scene each); REPS runs of each alternating, the pictures compared each time. The environment is
# the one-machine run of docs/DISTRIBUTED.md (shared memory, the ob1 PML). The floor, in the same rounds: the
# same two commands on a frame with next to no work (the teapot, 16 x 8, local mode: start, MPI_Init, the
# protocol, MPI_Finalize and exit against a process's start and exit; both write a PNG).
#   tests/bench/bench_mpi_overhead.sh BUILD_DIR [REPS [RENDER_ARGS...]]   (docs/PERFORMANCE.md "MPI rendering")
# RENDER_ARGS go to every render (e.g. --spp 4 for a frame of 4x the tracing).
set -euo pipefail
S="${1:?usage: $0 BUILD_DIR [REPS]}/pipeline/sylva"
REPS="${2:-3}"
shift $(( $# < 2 ? $# : 2 ))
EXTRA=("$@")
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_pml=ob1
ROOT=()
if [[ $(id -u) -eq 0 ]]; then ROOT=(--allow-run-as-root); fi
"$S" render --quiet -o "$OUT/warm.png" >/dev/null   # grow and light the species once (cache)
TEAPOT="$(dirname "$0")/../../resources/teapot.sylva.json"
TINY=("$TEAPOT" --width 16 --height 8 --mode local --quiet)
trace() { sed -n 's/^time: .*trace \([0-9.]*\) s$/\1/p'; }
single=() mpi=() each=() wall1=() wall2=() wall3=() floor1=() floor2=()
for ((i = 0; i < REPS; ++i)); do
  t0=$(date +%s.%N); s=$("$S" render "${EXTRA[@]}" --threads 2 --stats --quiet -o "$OUT/s.png" | trace); t1=$(date +%s.%N)
  m=$(mpirun "${ROOT[@]}" --oversubscribe --bind-to none -np 2 "$S" render "${EXTRA[@]}" --mpi --threads 1 --stats --quiet -o "$OUT/m.png" | trace)
  t2=$(date +%s.%N)
  e=$(mpirun "${ROOT[@]}" --oversubscribe --bind-to none -np 2 "$S" render "${EXTRA[@]}" --mpi --mpi-scene each --threads 1 --stats --quiet -o "$OUT/e.png" | trace)
  t3=$(date +%s.%N)
  "$S" render "${TINY[@]}" --threads 2 -o "$OUT/fs.png" >/dev/null
  t4=$(date +%s.%N)
  mpirun "${ROOT[@]}" --oversubscribe --bind-to none -np 2 "$S" render "${TINY[@]}" --mpi --threads 1 -o "$OUT/fm.png" >/dev/null
  t5=$(date +%s.%N)
  floor1+=("$(echo "$t4 - $t3" | bc)") floor2+=("$(echo "$t5 - $t4" | bc)")
  cmp -s "$OUT/fs.png" "$OUT/fm.png" || { echo "the pictures differ (floor)" >&2; exit 1; }
  cmp -s "$OUT/s.png" "$OUT/m.png" || { echo "the pictures differ (broadcast)" >&2; exit 1; }
  cmp -s "$OUT/s.png" "$OUT/e.png" || { echo "the pictures differ (each)" >&2; exit 1; }
  single+=("$s") mpi+=("$m") each+=("$e")
  wall1+=("$(echo "$t1 - $t0" | bc)") wall2+=("$(echo "$t2 - $t1" | bc)") wall3+=("$(echo "$t3 - $t2" | bc)")
  echo "run $i: single trace $s s wall ${wall1[-1]} s; 2 ranks (broadcast scene) trace $m s wall ${wall2[-1]} s; (each builds) trace $e s wall ${wall3[-1]} s; floor: single ${floor1[-1]} s, 2 ranks ${floor2[-1]} s"
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
ms=$(median "${single[@]}") mm=$(median "${mpi[@]}") me=$(median "${each[@]}")
w1=$(median "${wall1[@]}") w2=$(median "${wall2[@]}") w3=$(median "${wall3[@]}")
f1=$(median "${floor1[@]}") f2=$(median "${floor2[@]}")
echo "single_trace_s=$ms"
echo "mpi2_trace_s=$mm"
echo "mpi2_each_trace_s=$me"
echo "single_wall_s=$w1"
echo "mpi2_wall_s=$w2"
echo "mpi2_each_wall_s=$w3"
echo "trace_ratio=$(echo "scale=3; $mm / $ms" | bc)"
echo "wall_ratio=$(echo "scale=3; $w2 / $w1" | bc)"
echo "each_trace_ratio=$(echo "scale=3; $me / $ms" | bc)"
echo "each_wall_ratio=$(echo "scale=3; $w3 / $w1" | bc)"
echo "floor_single_wall_s=$f1"
echo "floor_mpi2_wall_s=$f2"
echo "floor_s=$(echo "scale=3; $f2 - $f1" | bc)"
echo "floor_ratio=$(echo "scale=3; ($w1 + $f2 - $f1) / $w1" | bc)"
echo "beyond_floor_ratio=$(echo "scale=3; $w2 / ($w1 + $f2 - $f1)" | bc)"
