#!/usr/bin/env bash
# `cmake --install` into a temporary prefix, then the installed binary and Python module run from
# outside the source tree, with a bare environment: no path into the checkout or the build folder.
#   tests/install/test_install.sh BUILD_DIR PYTHON (PYTHON empty: built without the module)
set -euo pipefail
build="$(cd "$1" && pwd)"
python="${2:-}"
source_dir="$(cd "$(dirname "$0")/../.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "test_install: FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log"
prefix="$tmp/prefix"
for f in bin/fourierflare share/man/man1/fourierflare.1 share/fourierflare/night-street.exr \
         share/fourierflare/lenses/double-gauss-50mm-f2.lens share/fourierflare/glass/schott.glass; do
  [ -f "$prefix/$f" ] || fail "not installed: $f"
done
# Nothing installed names the checkout or the build folder.
if grep -r -l -a -F -e "$source_dir" -e "$build" "$prefix" > "$tmp/refs"; then
  fail "installed files name the source or build folder: $(cat "$tmp/refs")"
fi
head -1 "$prefix/share/man/man1/fourierflare.1" | grep -q '^\.TH FOURIERFLARE 1 ' || fail "man page header"
for c in lens ghosts render table export compare simulate "lens info" "lens convert"; do
  grep -q "^\.SS \"fourierflare $c\"" "$prefix/share/man/man1/fourierflare.1" || fail "man page lacks '$c'"
done

mkdir -p "$tmp/work" "$tmp/home"
cd "$tmp/work"
bare=(env -i "PATH=$prefix/bin:/usr/bin:/bin" "HOME=$tmp/home" "FF_CACHE_DIR=$tmp/cache")
version="$("${bare[@]}" fourierflare --version)"
[ "$version" = "$("$build/src/cli/fourierflare" --version)" ] || fail "installed version '$version'"
# A bundled lens by name; the plate from share/.
"${bare[@]}" fourierflare lens info double-gauss-50mm-f2 > info.txt
grep -q "file: $prefix/share/fourierflare/lenses/double-gauss-50mm-f2.lens" info.txt || fail "lens by name: $(head -3 info.txt)"
"${bare[@]}" fourierflare -q simulate --lens double-gauss-50mm-f2 --plate "$prefix/share/fourierflare/night-street.exr" \
  -o night-street.exr --preview night-street.png
[ -s night-street.exr ] && [ -s night-street.png ] || fail "simulate wrote no output"
iinfo -v night-street.exr | grep -q "ghosts.R" || fail "no ghosts layer in the output"
# A name that is no installed lens: exit 2, saying where it looked.
set +e
"${bare[@]}" fourierflare lens info no-such-lens 2> err.txt
rc=$?
set -e
[ $rc -eq 2 ] && grep -q "no lens of that name in $prefix/share/fourierflare/lenses" err.txt || fail "unknown name: rc $rc, $(cat err.txt)"

if [ -n "$python" ]; then
  module="$(find "$prefix" -name 'fourierflare*.so')"
  [ -n "$module" ] || fail "the Python module was not installed"
  site="$(dirname "$module")"
  env -i "PATH=/usr/bin:/bin" "HOME=$tmp/home" "FF_CACHE_DIR=$tmp/cache" "PYTHONPATH=$site" "$python" -c "
import fourierflare as ff
assert ff.__file__.startswith('$prefix/'), ff.__file__
assert 'fourierflare ' + ff.__version__ == '$version', ff.__version__
lens = ff.Lens.load('double-gauss-50mm-f2')
image = ff.render(lens, [(60.0, 30.0)], (96, 64), 'fitted', table_grid=8, table_angles=9)
assert image.shape == (64, 96, 3) and image.sum() > 0
print('python ok', ff.__file__)
"
fi

# The installed tree moved elsewhere still finds its data (paths relative to the binaries).
mv "$prefix" "$tmp/moved"
env -i "PATH=$tmp/moved/bin:/usr/bin:/bin" "HOME=$tmp/home" fourierflare lens info cooke-triplet-50mm-f5 > moved.txt
grep -q "file: $tmp/moved/share/fourierflare/lenses/cooke-triplet-50mm-f5.lens" moved.txt || fail "moved tree"
echo "test_install: ok"
