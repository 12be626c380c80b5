#pragma once
#include <string>

namespace partita::fem {

// The BLAS that CHOLMOD's supernodal kernels call, as this process sees it at run time.
//
// Which library answers a BLAS call is decided when the program is loaded: on Debian,
// libblas.so.3 and liblapack.so.3 are alternatives (reference BLAS, OpenBLAS serial, pthreads or
// OpenMP, BLIS, ...). partita's executables carry the serial OpenBLAS's folder as their run path
// when the build found it (CMake PARTITA_BLAS_DIR), so the same library answers whatever the
// alternatives select; use_serial_blas() then makes sure that whichever BLAS is loaded runs each
// call on the calling thread. A BLAS that splits a call over threads sums in an order that
// depends on the thread count, and the factor then depends on the machine's cores.
struct BlasInfo {
  std::string name;       ///< "OpenBLAS 0.3.21 ...", "BLIS 0.9.0", "Intel MKL ...", "reference BLAS", "none"
  std::string library;    ///< the file that provides dgemm_ ("" when no BLAS is loaded)
  std::string threading;  ///< how the library can thread: "serial", "pthreads", "OpenMP", "unknown"
  int threads = 1;        ///< threads one BLAS call uses now
};

// What is loaded now, changing nothing.
BlasInfo blas_info();

// Sets the loaded BLAS to one thread per call through its own API (OpenBLAS, BLIS, MKL; the
// reference BLAS and ATLAS are serial already) and returns what is loaded afterwards. The
// OpenMP threads of the caller are left as they were. Safe to call from several threads and
// more than once; the SparseFactorisation with CHOLMOD calls it before its first analysis.
BlasInfo use_serial_blas();

// The run path the build gave the executables for the BLAS ("" when none: the alternatives'
// libblas.so.3 is then loaded).
std::string configured_blas_dir();

}  // namespace partita::fem
