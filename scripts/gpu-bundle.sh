#!/usr/bin/env bash
# Packs the GPU checks into build/gpu-bundle and build/gpu-bundle.tar.gz (what a GPU machine is sent,
# docs/gpu.md, "Running the checks on a GPU"):
# test_gpu, bench_gl, bench_diffraction and bench_simulate_gl from build/release, the shared libraries
# they load that a GPU machine's base system may lack (everything but the C and C++ runtimes), and
# Debian's glvnd EGL dispatch (NVIDIA's driver brings its own vendor library and ICD file). Then
# build/gpu-bundle/run.sh, run from the repository root on the GPU machine, runs the GL tests, the
# benches and the end-to-end simulate bench, writing their output under $OUT (or ./gpu-out).
#   scripts/build.sh release && scripts/gpu-bundle.sh
set -euo pipefail
cd "$(dirname "$0")/.."
b=build/release
bins=("$b/tests/test_gpu" "$b/bench/bench_gl" "$b/bench/bench_diffraction" "$b/bench/bench_simulate_gl")
for f in "${bins[@]}"; do [ -x "$f" ] || { echo "gpu-bundle: $f is missing: run scripts/build.sh release" >&2; exit 2; }; done
out=build/gpu-bundle
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
cp "${bins[@]}" "$out/bin/"
# The machine's own C and C++ runtimes and loader stay (newer there than here is compatible).
skip='^(libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|ld-linux-x86-64)\.so'
for f in "${bins[@]}"; do ldd "$f"; done | awk '/=> \//{print $3}' | sort -u | while read -r lib; do
  name=$(basename "$lib")
  [[ $name =~ $skip ]] || cp -L "$lib" "$out/lib/"
done
for lib in libEGL.so.1 libGLdispatch.so.0 libOpenGL.so.0; do
  path=$(ldconfig -p | awk -v n="$lib" '$1 == n && /x86-64/ {print $NF; exit}')
  [ -n "$path" ] && cp -L "$path" "$out/lib/"
done
cat > "$out/run.sh" <<'RUN'
#!/usr/bin/env bash
# From the repository root: bash build/gpu-bundle/run.sh (writes under $OUT, else ./gpu-out).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${OUT:-gpu-out}
mkdir -p "$out"
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export FF_CACHE_DIR=${FF_CACHE_DIR:-/tmp/fourierflare-gpu-cache} # the tables: not sent back
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv > "$out/gpu.txt" 2>&1
"$here/bin/test_gpu" --gtest_brief=1 > "$out/test_gpu.txt" 2>&1; echo "test_gpu: exit $?" >> "$out/summary.txt"
"$here/bin/bench_gl" --benchmark_min_time=0.3 > "$out/bench_gl.txt" 2>&1; echo "bench_gl: exit $?" >> "$out/summary.txt"
"$here/bin/bench_diffraction" --benchmark_filter='Convolve' > "$out/bench_diffraction.txt" 2>&1
echo "bench_diffraction: exit $?" >> "$out/summary.txt"
"$here/bin/bench_simulate_gl" > "$out/bench_simulate_gl.txt" 2>&1; echo "bench_simulate_gl: exit $?" >> "$out/summary.txt"
cat "$out/summary.txt"
RUN
chmod +x "$out/run.sh"
tar -C build -czf build/gpu-bundle.tar.gz gpu-bundle
size=$(stat -c %s build/gpu-bundle.tar.gz)
echo "gpu-bundle: $(du -sh "$out" | cut -f1) in $out ($(ls "$out/lib" | wc -l) libraries); build/gpu-bundle.tar.gz $((size / 1048576)) MiB"
