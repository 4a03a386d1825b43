#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# scripts/bundle end to end: packs BUILD_DIR's tgraph (no second build), unpacks it into a
# temporary folder and runs it from there with an empty environment (env -i): --version and a
# checked live run of fig2 on 2 threads. Under LD_DEBUG=files, every shared object the run
# loads (linked or dlopen'ed) must come from the bundle's lib/ or be glibc's.
#   bundle_test.sh SCRIPTS_BUNDLE BUILD_DIR
set -euo pipefail
bundle="$(realpath "$1")"
build="$(realpath "$2")"
d="$(mktemp -d)"
trap 'rm -rf "$d"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$bundle" "$d/tgraph-test.tar.xz" "$build" >"$d/bundle.log"
mkdir "$d/unpacked"
tar -C "$d/unpacked" -xJf "$d/tgraph-test.tar.xz"
top="$d/unpacked/tgraph-test"
[ -x "$top/run" ] && [ -x "$top/bin/tgraph" ] || fail "no run wrapper or bin/tgraph in the bundle"
ls "$top/lib"/*.so* >/dev/null 2>&1 || fail "no libraries in the bundle's lib/"
for glibc in libc.so.6 libm.so.6 ld-linux-x86-64.so.2; do
  [ ! -e "$top/lib/$glibc" ] || fail "glibc's $glibc was bundled"
done

cd "$d"  # not the source tree or the build folder
version="$(env -i "$top/run" --version)"
[ "$version" = "$("$build/apps/tgraph" --version)" ] || fail "run --version printed '$version'"

out="$(env -i "$top/run" run --scene fig2 --threads 2 --check)" || fail "run exited $?: $out"
grep -q "^run fig2: .* 2 threads" <<<"$out" || fail "no run line for fig2 on 2 threads: $out"
grep -q "check against .*: identical bit for bit" <<<"$out" || fail "check not identical: $out"

# Where the loader found each object it mapped: the last file it tried before "generating link
# map" (LD_DEBUG=libs,files), or the path itself for an object dlopen'ed by path.
env -i LD_DEBUG=libs,files "$top/run" run --scene fig2 --threads 2 --check >/dev/null 2>"$d/ld.log"
loaded="$(awk '/trying file=/ { sub(/.*trying file=/, ""); last = $0 }
               /generating link map/ { match($0, /file=[^ ]+/); n = substr($0, RSTART + 5, RLENGTH - 5)
                                       print (n ~ /^\//) ? n : last }' "$d/ld.log")"
[ -n "$loaded" ] || fail "LD_DEBUG=files listed no objects"
outside=()
while read -r f; do
  case "$(basename "$f")" in
    ld-linux* | libc.so* | libm.so* | libmvec.so* | libpthread.so* | libdl.so* | librt.so* | \
      libresolv.so* | libutil.so* | libanl.so* | libnss_* ) ;;
    *) [ "${f#"$top/"}" != "$f" ] || outside+=("$f") ;;
  esac
done <<<"$loaded"
[ ${#outside[@]} -eq 0 ] || fail "loaded from outside the bundle: ${outside[*]}"
echo "ok: $(tail -1 "$d/bundle.log")"
