#!/usr/bin/env bash
# partita: one script for set-up, build, the default run and the test suite.
#
#   ./build.sh run [CASE.yaml] [partita run options]   install what is missing, build, run a case
#                                                      (default: the seed-000 steel plate case)
#   ./build.sh test [--sanitize]                       install what is missing, build, run ctest
#                                                      (--sanitize: a second build with
#                                                       -fsanitize=address,undefined in build-asan/)
#   ./build.sh deps                                    only install the Debian packages
#
# Works on a fresh Debian 12 machine as root or as a user with sudo. Nothing is downloaded but
# Debian packages; nothing is installed when everything is already there.
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES=(cmake ninja-build g++ pkg-config libeigen3-dev libyaml-cpp-dev libspdlog-dev libfmt-dev
          catch2 libcli11-dev libnanoflann-dev python3 python3-numpy python3-matplotlib
          python3-vtk9)
DEFAULT_CASE=cases/uniaxial_compaction/steel.yaml
JOBS=${JOBS:-$(nproc)}

install_deps() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
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
    if [ "${1:-}" = "--sanitize" ]; then
      # Sanitizers: -O1 with assertions on (no NDEBUG), benchmarks not built; ASan's leak checker on.
      # (-O1 builds in about 4.5 min on 2 cores and runs the suite in about 2 min.)
      configure_and_build build-asan -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O1" \
        -DPARTITA_SANITIZE=ON -DPARTITA_BUILD_BENCH=OFF
      export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
      ctest --test-dir build-asan --output-on-failure -j "$JOBS"
    else
      configure_and_build build -DCMAKE_BUILD_TYPE=Release
      ctest --test-dir build --output-on-failure -j "$JOBS"
    fi
    ;;
  *)
    echo "usage: ./build.sh run [CASE.yaml] [options] | ./build.sh test [--sanitize] | ./build.sh deps" >&2
    exit 2
    ;;
esac
