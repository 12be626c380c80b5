# Sourced by the device scripts (scaling.sh, parallel_threads.sh, mpi.sh), in the repository root:
# unpacks .dev/bundle.tar.gz (bench/device/pack.sh) into $dev (/tmp/partita-dev; nothing outside
# /tmp) and points the dynamic loader at its libraries. Returns 1 without a bundle.
dev=/tmp/partita-dev
unpack_bundle() {
  rm -rf "$dev" && mkdir -p "$dev"
  tar -C "$dev" -xzf .dev/bundle.tar.gz || return 1
  export LD_LIBRARY_PATH=$dev/lib
  unset OMP_WAIT_POLICY OMP_NUM_THREADS
}

# The tests reach files and the app through paths compiled in where the bundle was packed
# (tests/CMakeLists.txt: PARTITA_SOURCE_DIR, PARTITA_EXECUTABLE; app/: PARTITA_PLOT_SCRIPT): the
# source tree as this checkout (a link to $PWD) and the app as the bundle's, where they do not
# exist here. Prints what it linked.
provide_build_paths() {
  local script src exe
  # the source directory: the app's plot script is <source>/app/plot_monitors.py
  script=$(strings "$dev/bin/partita" | grep -m1 -E '^/.*/app/plot_monitors\.py$' || true)
  src=${script%/app/plot_monitors.py}
  if [[ -n $script && ! -e $src ]]; then
    mkdir -p "$(dirname "$src")" && ln -sfn "$PWD" "$src" && echo "linked $src -> $PWD"
  fi
  # the app the tests run: <binary dir>/app/partita (under the source link when the build was)
  exe=$(strings "$dev/bin/partita_tests" 2>/dev/null | grep -m1 -E '^/.*/app/partita$' || true)
  if [[ -n $exe && ! -e $exe ]]; then
    mkdir -p "$(dirname "$exe")" && ln -sfn "$dev/bin/partita" "$exe" &&
      echo "linked $exe -> $dev/bin/partita"
  fi
}
