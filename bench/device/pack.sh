#!/usr/bin/env bash
# Packs what the 16-core measurements need for the lent device machine (no Debian packages there,
# nothing can be fetched): the Release binaries of build/, the shared libraries they link that are
# not the C library, and the peer beds. Writes .dev/bundle.tar.gz (ignored through
# .git/info/exclude) and prints the device call. See bench/README.md, "16 cores".
#   bench/device/pack.sh [PEER_DATA_DIR]   (default ../shared/bench/peers/dem/data)
#   bench/device/pack.sh --threads-only     partita alone (bench/device/parallel_threads.sh)
set -euo pipefail
root=$(git rev-parse --show-toplevel)
cd "$root"
only=0
[[ ${1:-} == --threads-only ]] && { only=1; shift; }
data=${1:-../shared/bench/peers/dem/data}
bins=(build/app/partita build/tests/partita_tests build/bench/dem/bench_dem_peers
      build/bench/fem/bench_fem_plate)
((only)) && bins=(build/app/partita)
# the binaries of the working tree as it is (nothing to do when current)
if [[ -f build/build.ninja ]]; then
  cmake --build build --target "${bins[@]##*/}" >/dev/null
fi
for b in "${bins[@]}"; do
  [[ -x $b ]] || { echo "pack.sh: $b is missing: build first (./build.sh test)" >&2; exit 1; }
done
if ((!only)); then
  for f in bed_large.data bed_small.data; do
    [[ -f $data/$f ]] || { echo "pack.sh: $data/$f is missing (the peer beds)" >&2; exit 1; }
  done
fi
exclude=$(git rev-parse --git-path info/exclude)  # (a worktree's too)
mkdir -p "$(dirname "$exclude")"
grep -qx '/.dev/' "$exclude" 2>/dev/null || echo '/.dev/' >> "$exclude"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/data" "$stage/share/partita"
for b in "${bins[@]}"; do strip -o "$stage/bin/$(basename "$b")" "$b"; done
# the app's plot scripts where an installed partita finds them (bin/../share/partita)
cp app/plot_monitors.py app/plot_sweep.py "$stage/share/partita/"
# the libraries that ELF files $@ load, but the C library and the loader (the device's own are
# newer), into $stage/lib
copy_libraries() {
  ldd "$@" | awk '$3 ~ /^\// {print $3}' | sort -u |
    grep -v -E '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*)\.so' |
    while read -r lib; do cp -L "$lib" "$stage/lib/"; done
}
copy_libraries "${bins[@]}"
((only)) || cp "$data"/bed_large.data "$data"/bed_small.data "$stage/data/"
mkdir -p .dev
tar -C "$stage" -czf .dev/bundle.tar.gz bin lib data share
echo "pack.sh: .dev/bundle.tar.gz $(du -h .dev/bundle.tar.gz | cut -f1) (binaries of $(git rev-parse --short HEAD))"
if ((only)); then
  echo "device call: run(command='bash bench/device/parallel_threads.sh', carry=['.dev'], timeout_s=300)"
else
  echo "device call: run(command='bash bench/device/scaling.sh', carry=['.dev'], timeout_s=540)"
fi
