#include "partita/fem/blas_runtime.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <mutex>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace partita::fem {

namespace {

// A function of the loaded BLAS, looked up by name in the process's global scope (nullptr when
// no loaded library exports it). The libraries' own headers are not needed: the few entry points
// used here have had these C signatures for many releases.
template <class F>
F lookup(const char* symbol) {
  return reinterpret_cast<F>(dlsym(RTLD_DEFAULT, symbol));
}

std::string library_of(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  if (address == nullptr) return {};
  Dl_info info{};
  if (dladdr(address, &info) == 0 || info.dli_fname == nullptr) return {};
  return info.dli_fname;
}

bool contains(const std::string& text, const char* part) {
  return text.find(part) != std::string::npos;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\n')) s.pop_back();
  return s;
}

// OpenBLAS: openblas_get_parallel() 0 = sequential build, 1 = pthreads, 2 = OpenMP.
struct OpenBlas {
  using GetConfig = char* (*)();
  using GetInt = int (*)();
  using SetThreads = void (*)(int);
  GetConfig config = lookup<GetConfig>("openblas_get_config");
  GetInt parallel = lookup<GetInt>("openblas_get_parallel");
  GetInt get_threads = lookup<GetInt>("openblas_get_num_threads");
  SetThreads set_threads = lookup<SetThreads>("openblas_set_num_threads");
  bool loaded() const { return config != nullptr; }
};

// BLIS (dim_t and gint_t are 64-bit in Debian's builds).
struct Blis {
  using Version = const char* (*)();
  using GetThreads = std::int64_t (*)();
  using SetThreads = void (*)(std::int64_t);
  using Enabled = std::int64_t (*)();
  Version version = lookup<Version>("bli_info_get_version_str");
  GetThreads get_threads = lookup<GetThreads>("bli_thread_get_num_threads");
  SetThreads set_threads = lookup<SetThreads>("bli_thread_set_num_threads");
  Enabled openmp = lookup<Enabled>("bli_info_get_enable_openmp");
  Enabled pthreads = lookup<Enabled>("bli_info_get_enable_pthreads");
  bool loaded() const { return version != nullptr; }
};

// Intel MKL's C entry points (the upper-case names are the functions behind mkl_* macros).
struct Mkl {
  using GetThreads = int (*)();
  using SetThreads = void (*)(int);
  using Version = void (*)(char*, int);
  GetThreads get_threads = lookup<GetThreads>("MKL_Get_Max_Threads");
  SetThreads set_threads = lookup<SetThreads>("MKL_Set_Num_Threads");
  Version version = lookup<Version>("MKL_Get_Version_String");
  bool loaded() const { return get_threads != nullptr; }
};

BlasInfo query() {
  BlasInfo info;
  info.library = library_of("dgemm_");
  if (const OpenBlas ob; ob.loaded()) {
    const std::string config = ob.config() ? ob.config() : "";
    info.name = trimmed(config.rfind("OpenBLAS", 0) == 0 ? config : "OpenBLAS " + config);
    const int mode = ob.parallel ? ob.parallel() : -1;
    info.threading = mode == 0 ? "serial" : mode == 1 ? "pthreads" : mode == 2 ? "OpenMP" : "unknown";
    info.threads = mode == 0 ? 1 : ob.get_threads ? ob.get_threads() : -1;
    return info;
  }
  if (const Blis blis; blis.loaded()) {
    info.name = std::string("BLIS ") + blis.version();
    const bool omp = blis.openmp && blis.openmp() != 0;
    const bool pth = blis.pthreads && blis.pthreads() != 0;
    info.threading = omp ? "OpenMP" : pth ? "pthreads" : "serial";
    info.threads = (omp || pth) && blis.get_threads
                       ? static_cast<int>(std::max<std::int64_t>(1, blis.get_threads()))
                       : 1;
    return info;
  }
  if (const Mkl mkl; mkl.loaded()) {
    std::array<char, 256> version{};
    if (mkl.version) mkl.version(version.data(), static_cast<int>(version.size()) - 1);
    info.name = version[0] ? trimmed(version.data()) : "Intel MKL";
    info.threading = "unknown";
    info.threads = mkl.get_threads();
    return info;
  }
  if (info.library.empty()) {
    info.name = "none";
    info.threading = "serial";
    return info;
  }
  // Netlib's reference BLAS and ATLAS (Debian's libatlas3-base) have no threads of their own.
  info.name = contains(info.library, "atlas")  ? "ATLAS"
              : contains(info.library, "/blas/") ? "reference BLAS"
                                                 : "unknown BLAS";
  info.threading = contains(info.name, "unknown") ? "unknown" : "serial";
  info.threads = 1;
  return info;
}

void pin_to_one_thread() {
#ifdef _OPENMP
  // OpenBLAS's and BLIS's OpenMP builds set the calling thread's OpenMP thread count along with
  // their own: keep the caller's
  const int caller_threads = omp_get_max_threads();
#endif
  if (const OpenBlas ob; ob.loaded()) {
    if (ob.set_threads && !(ob.parallel && ob.parallel() == 0)) ob.set_threads(1);
  } else if (const Blis blis; blis.loaded()) {
    if (blis.set_threads) blis.set_threads(1);
  } else if (const Mkl mkl; mkl.loaded()) {
    if (mkl.set_threads) mkl.set_threads(1);
  }
#ifdef _OPENMP
  if (omp_get_max_threads() != caller_threads) omp_set_num_threads(caller_threads);
#endif
}

}  // namespace

BlasInfo blas_info() { return query(); }

BlasInfo use_serial_blas() {
  static std::once_flag once;
  std::call_once(once, pin_to_one_thread);
  return query();
}

std::string configured_blas_dir() {
#ifdef PARTITA_BLAS_DIR
  return PARTITA_BLAS_DIR;
#else
  return {};
#endif
}

}  // namespace partita::fem
