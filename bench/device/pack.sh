#!/usr/bin/env bash
# Packs what the 16-core measurements need for the lent device machine (no Debian packages there,
# nothing can be fetched): the Release binaries of build/, the shared libraries they link that are
# not the C library, and the peer beds; with a partita built with MPI also OpenMPI's run-time and
# bench_mpi (bench/device/mpi.sh; about 5 MB more). Writes .dev/bundle.tar.gz (ignored through
# .git/info/exclude) and prints the device calls. See bench/README.md, "16 cores".
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
mkdir -p "$stage/bin" "$stage/lib" "$stage/data"
for b in "${bins[@]}"; do strip -o "$stage/bin/$(basename "$b")" "$b"; done
# (not the plot scripts: the tests' app finds them in the source tree, bundle.sh, and the timed
# runs of parallel_threads.sh and mpi.sh would otherwise draw their CSV files, seconds each)
# the libraries that ELF files $@ load, but the C library and the loader (the device's own are
# newer), into $stage/lib
copy_libraries() {
  ldd "$@" | awk '$3 ~ /^\// {print $3}' | sort -u |
    grep -v -E '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*)\.so' |
    while read -r lib; do cp -L "$lib" "$stage/lib/"; done
}
copy_libraries "${bins[@]}"
((only)) || cp "$data"/bed_large.data "$data"/bed_small.data "$stage/data/"
parts=(bin lib data)
# partita built with MPI (--participant): OpenMPI's launcher and run-time (Debian 12's openmpi-bin,
# libopenmpi3, libpmix2) under ompi/, relocated by bench/device/bundle.sh (use_bundled_mpi), and
# bench_mpi (bench/device/mpi.sh)
if [[ $(ldd build/app/partita) == *libmpi.so* ]]; then
  o=$stage/ompi ml=/usr/lib/x86_64-linux-gnu/openmpi/lib/openmpi3 pm=/usr/lib/x86_64-linux-gnu/pmix2
  for d in $ml /usr/share/openmpi /etc/openmpi $pm/lib/pmix $pm/share/pmix; do
    [[ -d $d ]] || { echo "pack.sh: $d is missing (apt-get install openmpi-bin)" >&2; exit 1; }
  done
  mkdir -p "$o/bin" "$o/lib" "$o/share" "$o/etc" "$o/pmix/lib" "$o/pmix/share"
  for b in orterun orted ompi_info; do cp -L "/usr/bin/$b" "$o/bin/"; done
  ln -s orterun "$o/bin/mpirun"
  cp -rL $ml "$o/lib/" && cp -rL /usr/share/openmpi "$o/share/" && cp -L /etc/openmpi/* "$o/etc/"
  cp -rL $pm/lib/pmix "$o/pmix/lib/" && cp -rL $pm/share/pmix $pm/share/pmix-mca-params.conf "$o/pmix/share/"
  copy_libraries "$o"/bin/orte* "$o"/bin/ompi_info "$o"/lib/openmpi3/*.so "$o"/pmix/lib/pmix/*.so
  [[ -f build/bench/mpi/bench_mpi ]] && cp build/bench/mpi/bench_mpi "$stage/bin/"
  parts+=(ompi)
fi
mkdir -p .dev
tar -C "$stage" -czf .dev/bundle.tar.gz "${parts[@]}"
echo "pack.sh: .dev/bundle.tar.gz $(du -h .dev/bundle.tar.gz | cut -f1) (binaries of $(git rev-parse --short HEAD))"
if ((only)); then
  echo "device call: run(command='bash bench/device/parallel_threads.sh', carry=['.dev'], timeout_s=300)"
else
  echo "device call: run(command='bash bench/device/scaling.sh', carry=['.dev'], timeout_s=540)"
fi
if [[ " ${parts[*]} " == *" ompi "* ]]; then
  echo "device call: run(command='bash bench/device/mpi.sh', carry=['.dev'], timeout_s=300)"
fi
