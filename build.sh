#!/usr/bin/env bash
# partita: one script for set-up, build, the default run and the test suite.
#
#   ./build.sh run [CASE.yaml] [partita run options]   install what is missing, build, run a case
#                                                      (default: the seed-000 steel plate case)
#   ./build.sh test [--sanitize]                       install what is missing, build, run ctest,
#                                                      print the build's, the tests' and the total time
#                                                      (--sanitize: a clang build with ASan, UBSan
#                                                       and libFuzzer instrumentation in build-asan/,
#                                                       the suite without the tests tagged [slow])
#   ./build.sh fuzz [SECONDS]                          install what is missing, build the libFuzzer
#                                                      harnesses of tests/fuzz in that same
#                                                      build-asan/, run each for SECONDS
#                                                      (default 60) from the seed inputs
#                                                      (SANITIZE_CXXFLAGS: optimisation, default -O1
#                                                       for the suite, -O0 for the harnesses)
#   ./build.sh deps                                    only install the Debian packages
#
# Works on a fresh Debian 12 machine as root or as a user with sudo. Nothing is downloaded but
# Debian packages; nothing is installed when everything is already there.
set -euo pipefail
cd "$(dirname "$0")"

# libsuitesparse-dev: CHOLMOD, the FEM's supernodal sparse Cholesky (optional: without it the
# build falls back to Eigen's solver). libopenblas0-serial: the BLAS CHOLMOD's supernodes run on
# (Debian's reference BLAS makes the factorisation about 4x slower). Which BLAS answers is not
# left to Debian's libblas.so.3 alternative: other packages can pull in the threaded OpenBLAS
# (libopenblas0-pthread outranks the serial one), whose sums follow the cores, so a plate
# factorised in a process of its own would give other bits than in a shared one. The build
# (solvers/fem/CMakeLists.txt, PARTITA_BLAS_DIR) gives the executables the serial OpenBLAS's
# folder as their run path, so this one package answers whatever the alternatives select (they
# stay as the machine's owner set them), and every run sets whatever BLAS is loaded to one thread
# per call through the BLAS's own API (fem::use_serial_blas; `--log-level debug` names the
# library and its threads). The results then depend neither on the thread count nor on which
# BLAS packages are installed, and restarts stay bit-identical.
PACKAGES=(cmake ninja-build g++ pkg-config libeigen3-dev libyaml-cpp-dev libspdlog-dev libfmt-dev
          catch2 libcli11-dev libnanoflann-dev python3 python3-numpy python3-matplotlib
          python3-vtk9 libsuitesparse-dev libopenblas0-serial zlib1g-dev
          libopenmpi-dev openmpi-bin bc procps
          python3-dev pybind11-dev python3-pybind11 python3-pandas python3-pytest python3-mpi4py)
# libopenmpi-dev, openmpi-bin: participants as processes (`partita run CASE --participant NAME`
# under mpirun); bc and procps (pgrep) for the MPI tests' script.
# python3-dev, pybind11-dev, python3-pybind11, python3-pandas, python3-pytest: the Python module
# (python/, docs/python.md) for Debian's python3, its DataFrames and its pytest suite;
# python3-mpi4py: the communicator a Python program may give partita.ExternalParticipant.
# Only for `./build.sh test --sanitize` and `./build.sh fuzz`: clang and its runtime libraries
# (libclang_rt.fuzzer, ASan, UBSan).
SANITIZE_PACKAGES=(clang libclang-rt-dev)
DEFAULT_CASE=cases/uniaxial_compaction/steel.yaml
JOBS=${JOBS:-$(nproc)}

install_deps() {  # extra packages...
  local missing=()
  for p in "${PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "build.sh: installing missing Debian packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "build.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo="sudo"
  fi
  $sudo apt-get update -q
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
}

configure_and_build() {  # dir, extra cmake args...
  local dir=$1; shift
  cmake -S . -B "$dir" -G Ninja "$@" >/dev/null
  cmake --build "$dir" -j "$JOBS"
}

# The sanitized build (build-asan/): clang, ASan + UBSan, libFuzzer coverage in every module, so
# one build serves the sanitized suite and the fuzz harnesses. Assertions on (no NDEBUG): checks
# inside the readers count as findings. -O1: the suite runs about ten times slower than Release.
# OpenMP off (clang's runtime is another package; races are a ThreadSanitizer matter).
configure_sanitized() {  # default optimisation, targets...
  local opt=$1; shift
  install_deps "${SANITIZE_PACKAGES[@]}"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release \
    "-DCMAKE_CXX_FLAGS_RELEASE=${SANITIZE_CXXFLAGS:-$opt -gline-tables-only}" \
    -DCMAKE_CXX_COMPILER=clang++ -DPARTITA_FUZZ=ON -DPARTITA_BUILD_BENCH=OFF -DPARTITA_OPENMP=OFF >/dev/null
  cmake --build build-asan -j "$JOBS" "$@"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
}

cmd=${1:-run}
[ $# -gt 0 ] && shift
case "$cmd" in
  deps)
    install_deps
    ;;
  run)
    install_deps
    configure_and_build build -DCMAKE_BUILD_TYPE=Release
    case_file=$DEFAULT_CASE
    if [ $# -gt 0 ] && [[ "$1" != -* ]]; then case_file=$1; shift; fi
    exec ./build/app/partita run "$case_file" --threads "$JOBS" "$@"
    ;;
  test)
    install_deps
    # OpenMP threads sleep instead of spinning when they wait: tests run side by side (ctest -j)
    # and a spinning barrier on an oversubscribed core costs a whole scheduler slice. (Not for
    # `run`: a run alone on the machine is faster with the default, spinning, policy.)
    export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
    start=$(date +%s)
    dir=build
    if [ "${1:-}" = "--sanitize" ]; then
      dir=build-asan
      configure_sanitized -O1
    else
      configure_and_build build -DCMAKE_BUILD_TYPE=Release
    fi
    built=$(date +%s)
    status=0
    ctest --test-dir "$dir" --output-on-failure -j "$JOBS" || status=$?
    end=$(date +%s)
    echo "build.sh test: build $(( built - start )) s, tests $(( end - built )) s," \
         "total $(( end - start )) s (ctest exit status $status)"
    exit $status
    ;;
  fuzz)
    seconds=${1:-60}
    [[ "$seconds" =~ ^[0-9]+$ ]] || { echo "build.sh fuzz: SECONDS must be a whole number, found '$seconds'" >&2; exit 2; }
    # -O0: only the harnesses and their modules are built, at about 40 % of the CPU time of -O1
    configure_sanitized -O0 --target fuzz_stl fuzz_gmsh fuzz_case
    # Seeds: the test and case inputs of each kind, named after their paths (two cases may each
    # have a checks.yaml). The corpus grows in build-asan/fuzz/corpus/NAME; a finding is written to
    # build-asan/fuzz/findings/ and fails the command (fix it, then add the input to
    # tests/inputs/bad/ with its expected message).
    seed() {  # name, find expression...
      local dir=build-asan/fuzz/corpus/$1 f; shift
      mkdir -p "$dir"
      while IFS= read -r -d '' f; do cp -f "$f" "$dir/${f//\//_}"; done < <(find tests cases "$@" -print0)
    }
    seed stl -type f -iname '*.stl'
    seed gmsh -type f -iname '*.msh'
    seed case -type f \( -iname '*.yaml' -o -iname '*.yml' \)
    mkdir -p build-asan/fuzz/findings
    status=0
    for h in stl gmsh case; do
      echo "build.sh fuzz: fuzz_$h for $seconds s"
      ./build-asan/tests/fuzz/fuzz_$h -seed="${FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
        -max_len=65536 -print_final_stats=1 -artifact_prefix="build-asan/fuzz/findings/$h-" \
        -dict="tests/fuzz/$h.dict" "build-asan/fuzz/corpus/$h" 2>build-asan/fuzz/fuzz_$h.log || status=1
      grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|Done|==[0-9]+==ERROR|SUMMARY)' \
        build-asan/fuzz/fuzz_$h.log || true
      [ $status -eq 0 ] || { tail -n 60 build-asan/fuzz/fuzz_$h.log; ls build-asan/fuzz/findings; }
    done
    exit $status
    ;;
  *)
    echo "usage: ./build.sh run [CASE.yaml] [options] | ./build.sh test [--sanitize] | ./build.sh fuzz [SECONDS] | ./build.sh deps" >&2
    exit 2
    ;;
esac
