# Sourced by the device scripts (scaling.sh, parallel_threads.sh, mpi.sh), in the repository root.
dev=/tmp/partita-dev

# The script's log, $OUT/NAME (./NAME without $OUT), emptied; say: a line to it and the terminal.
open_log() {
  log=${OUT:-.}/$1
  : > "$log"
}
say() { echo "$*" | tee -a "$log"; }

# Unpacks .dev/bundle.tar.gz (bench/device/pack.sh) into $dev (nothing outside /tmp) and points the
# dynamic loader at its libraries. Returns 1 without a bundle.
unpack_bundle() {
  rm -rf "$dev" && mkdir -p "$dev"
  tar -C "$dev" -xzf .dev/bundle.tar.gz ||
    { say "no .dev/bundle.tar.gz: run bench/device/pack.sh here first"; return 1; }
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

# OpenMPI from the bundle (pack.sh copies Debian 12's 4.1 launcher, plugins, help files and
# configuration under $dev/ompi, their libraries into $dev/lib): OpenMPI and PMIx find their
# installation through these variables instead of the paths compiled in (/usr, /etc/openmpi,
# /usr/lib/x86_64-linux-gnu/{openmpi,pmix2}). Returns 1 when the bundle has no OpenMPI.
use_bundled_mpi() {
  local o=$dev/ompi
  [[ -x $o/bin/orterun ]] || return 1
  export OPAL_PREFIX=$o OPAL_EXEC_PREFIX=$o OPAL_BINDIR=$o/bin OPAL_SBINDIR=$o/bin \
    OPAL_LIBEXECDIR=$o/bin OPAL_LIBDIR=$dev/lib OPAL_PKGLIBDIR=$o/lib/openmpi3 \
    OPAL_DATAROOTDIR=$o/share OPAL_DATADIR=$o/share OPAL_PKGDATADIR=$o/share/openmpi \
    OPAL_SYSCONFDIR=$o/etc
  export OMPI_MCA_mca_base_component_path=$o/lib/openmpi3
  export PMIX_PREFIX=$o/pmix PMIX_EXEC_PREFIX=$o/pmix PMIX_LIBDIR=$o/pmix/lib \
    PMIX_PKGLIBDIR=$o/pmix/lib/pmix PMIX_DATAROOTDIR=$o/pmix/share PMIX_DATADIR=$o/pmix/share \
    PMIX_PKGDATADIR=$o/pmix/share/pmix PMIX_SYSCONFDIR=$o/pmix/share
  export PMIX_MCA_mca_base_component_path=$o/pmix/lib/pmix
  # hwloc's optional plugins (PCI, GPUs) are not needed to place two processes: none
  export HWLOC_PLUGINS_PATH=$o/hwloc
  export PATH=$o/bin:$PATH
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
}
