#!/usr/bin/env bash
# The GPU backend's benchmark (docs/performance.md): the same scenes on the GPU and on all of
# the host's cores, one after the other, with each run's summary (projfluid run --stats) kept
# as JSON and a table of wall time per simulated second, time per step and its stages.
#
#   bench/gpu/run.sh BIN [OUT] [quick]
#
# BIN is a projfluid command line built with the GPU backend
# (`cargo build --release --features gpu --bin projfluid`), OUT the folder for the JSON
# summaries and the table (default: $OUT, else bench-gpu-out). `quick` runs small scenes
# only, to try the script on a software Vulkan device (Mesa's lavapipe).
#
# On the GPU the stages' times are the device's own, from timestamps around its passes.
#
# The cases: dam_break_30k for 1 s (real time on the GPU is the goal), obstacle_298k and
# dam_break_1m for a fixed number of steps on both backends (the GPU ≥ 10 times the cores),
# and bench/gpu/dam_break_10m.json for a few steps on the GPU (it fits and runs). Each run has
# a time limit, so that the whole script ends within 9 minutes (540 s of limits).
#
# Where the Vulkan loader is missing and a folder .gl of its Debian packages is at hand
# (libvulkan1 and its kin, unpacked into /), it is unpacked first.
set -uo pipefail
cd "$(dirname "$0")/../.."
bin="${1:?usage: bench/gpu/run.sh BIN [OUT] [quick]}"
out="${2:-${OUT:-bench-gpu-out}}"
mode="${3:-full}"
mkdir -p "$out"
if ! /sbin/ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1 ' && [ -d .gl ]; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] && [ -z "${VK_DRIVER_FILES:-}" ]; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L
cores="$(nproc)"
echo "host: $cores cores; $(uname -m)"

# case NAME SCENE LIMIT_SECONDS ARGS…: one run, its summary in $out/NAME.json.
case_run() {
  local name="$1" scene="$2" limit="$3"
  shift 3
  echo "== $name: $scene $*"
  local started=$SECONDS
  timeout "$limit" "$bin" run "$scene" --stats "$out/$name.json" "$@" >"$out/$name.log" 2>&1
  local rc=$?
  echo "   exit $rc after $((SECONDS - started)) s"
  [ "$rc" -eq 0 ] || tail -n 5 "$out/$name.log"
}

if [ "$mode" = quick ]; then
  case_run small_gpu dam_break_small 120 --backend gpu --duration 0.1
  case_run small_cpu dam_break_small 120 --threads "$cores" --duration 0.1
  case_run honey_gpu honey_dam_break 120 --backend gpu --steps 10
  case_run honey_cpu honey_dam_break 120 --threads "$cores" --steps 10
else
  case_run 30k_gpu dam_break_30k 120 --backend gpu --duration 1.0
  case_run 30k_cpu dam_break_30k 45 --threads "$cores" --duration 1.0
  case_run 298k_gpu obstacle_298k 60 --backend gpu --steps 40
  case_run 298k_cpu obstacle_298k 60 --threads "$cores" --steps 40
  case_run 1m_gpu dam_break_1m 60 --backend gpu --steps 30
  case_run 1m_cpu dam_break_1m 75 --threads "$cores" --steps 30
  case_run 10m_gpu bench/gpu/dam_break_10m.json 120 --backend gpu --steps 5
fi

# The table, from the summaries that were written.
python3 - "$out" <<'PY' | tee "$out/table.md"
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
print("| run | backend | threads | particles | steps | simulated s | wall s per simulated s "
      "| ms per step | outer iterations | stages ms (search, local, global, rest) | density error |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for path in sorted(out.glob("*.json")):
    s = json.loads(path.read_text())
    wall = s["wall_ms_per_step"] * s["steps"] / 1000.0
    per_second = wall / s["sim_time"] if s["sim_time"] > 0 else float("nan")
    stages = ", ".join(f"{t:.2f}" for t in s["ms_per_step_breakdown"])
    print(f"| {path.stem} | {s['backend']} | {s['threads']} | {s['particles']} | {s['steps']} "
          f"| {s['sim_time']:.3f} | {per_second:.2f} | {s['wall_ms_per_step']:.2f} "
          f"| {s['outer_iterations_mean']:.1f} | {stages} "
          f"| {s['density_error_avg_percent']:.3f} % |")
PY
