#!/usr/bin/env bash
# The Debian package: built by CPack from BUILD_DIR, its file list and computed dependencies checked,
# installed with dpkg into a scratch root (its own dpkg database), the installed `fourierflare
# simulate` and `import fourierflare` run from there, then purged: nothing left behind.
#   tests/install/test_deb.sh BUILD_DIR PYTHON
set -euo pipefail
build="$(cd "$1" && pwd)"
python="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "test_deb: FAIL: $*" >&2; exit 1; }
command -v dpkg-shlibdeps > /dev/null || { echo "test_deb: dpkg-shlibdeps (dpkg-dev) missing"; exit 1; }

(cd "$build" && cpack -G DEB -B "$tmp/pkg" > "$tmp/cpack.log" 2>&1) || { cat "$tmp/cpack.log"; fail "cpack"; }
deb="$(ls "$tmp"/pkg/fourierflare_*.deb)"
pyver="$("$python" -c 'import sys; print("python%d.%d" % sys.version_info[:2])')"

# The file list.
dpkg-deb -c "$deb" | awk '{print $6}' > "$tmp/files"
for f in ./usr/bin/fourierflare ./usr/share/man/man1/fourierflare.1 ./usr/share/fourierflare/night-street.exr \
         ./usr/share/fourierflare/lenses/double-gauss-50mm-f2.lens ./usr/share/fourierflare/glass/schott.glass; do
  grep -qx -- "$f" "$tmp/files" || fail "the package lacks $f"
done
grep -q "^\./usr/lib/$pyver/dist-packages/fourierflare\..*\.so$" "$tmp/files" || fail "no module for $pyver"

# Every shared library the binary and the module name (DT_NEEDED) comes from a package the .deb depends on, or
# one of the alternatives of a metapackage it depends on (libopenblas0: libopenblas0-pthread | ...).
depends="$(dpkg-deb -f "$deb" Depends)"
echo "test_deb: Depends: $depends"
names=" $(echo "$depends" | tr ',|' '\n\n' | sed 's/(.*)//; s/ //g' | tr '\n' ' ') "
dpkg-deb -x "$deb" "$tmp/x"
for object in "$tmp/x/usr/bin/fourierflare" "$tmp"/x/usr/lib/"$pyver"/dist-packages/fourierflare*.so; do
  ldd "$object" > "$tmp/ldd"
  for needed in $(readelf -d "$object" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    lib="$(awk -v n="$needed" '($1 == n && $2 == "=>") {print $3} ($1 ~ "/" n "$") {print $1}' "$tmp/ldd" | head -1)"
    [ -n "$lib" ] || fail "$(basename "$object") needs $needed, which does not resolve"
    real="$(readlink -f "$lib")"
    pkg="$(dpkg -S "$real" 2>/dev/null | head -1 | cut -d: -f1)" || true
    [ -n "$pkg" ] || pkg="$(dpkg -S "$lib" 2>/dev/null | head -1 | cut -d: -f1)" || true
    [ -n "$pkg" ] || fail "no package owns $lib"
    ok=0
    case "$names" in *" $pkg "*) ok=1 ;; esac
    for n in $names; do
      dpkg-query -W -f='${Depends}' "$n" 2>/dev/null | tr ',|' '\n\n' | sed 's/(.*)//; s/ //g' | grep -qx -- "$pkg" && ok=1
    done
    [ $ok -eq 1 ] || fail "$(basename "$object") loads $lib from $pkg, which the package does not depend on"
  done
done
# Each dependency is a package this machine has (the one the build linked against).
for n in $names; do dpkg-query -W "$n" > /dev/null 2>&1 || fail "depends on $n, which is no package here"; done

# Installed with dpkg into a scratch root with its own database (its dependencies are this machine's).
root="$tmp/root"
mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates" "$root/var/lib/dpkg/triggers"
touch "$root/var/lib/dpkg/status"
dpkg --root="$root" --force-not-root --force-depends -i "$deb" > "$tmp/dpkg.log" 2>&1 || { cat "$tmp/dpkg.log"; fail "dpkg -i"; }
dpkg-query --admindir="$root/var/lib/dpkg" -W -f='${Status}\n' fourierflare | grep -q "install ok installed" || fail "not installed"
mkdir -p "$tmp/work" "$tmp/home" && cd "$tmp/work"
env -i "PATH=$root/usr/bin:/usr/bin:/bin" "HOME=$tmp/home" "FF_CACHE_DIR=$tmp/cache" \
  fourierflare -q simulate --lens double-gauss-50mm-f2 --plate "$root/usr/share/fourierflare/night-street.exr" -o out.exr
[ -s out.exr ] || fail "the installed simulate wrote nothing"
env -i "PATH=/usr/bin:/bin" "HOME=$tmp/home" "PYTHONPATH=$root/usr/lib/$pyver/dist-packages" "$python" -c "
import fourierflare as ff
assert ff.__file__.startswith('$root/usr/lib/'), ff.__file__
print('test_deb: import fourierflare', ff.__version__, 'from', ff.__file__)
assert ff.Lens.load('cooke-triplet-50mm-f5').name
"
# Purged cleanly: no file of the package left.
dpkg --root="$root" --force-not-root --purge fourierflare > "$tmp/purge.log" 2>&1 || { cat "$tmp/purge.log"; fail "dpkg --purge"; }
left="$(find "$root" -path "$root/var" -prune -o -type f -print)"
[ -z "$left" ] || fail "left after purge: $left"
echo "test_deb: ok ($(basename "$deb"), $(stat -c %s "$deb") bytes)"
