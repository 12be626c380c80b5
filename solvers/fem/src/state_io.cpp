#include "partita/fem/state_io.hpp"

#include <cstdint>
#include <cstring>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

constexpr char kMagic[8] = {'P', 'F', 'E', 'M', 'S', 'T', 'A', 'T'};
// Guards against absurd lengths read from a damaged file (2^40 values).
constexpr std::uint64_t kMaxLength = std::uint64_t{1} << 40;

class Writer {
 public:
  explicit Writer(std::ostream& out) : out_(out) {}
  void raw(const void* p, std::size_t n) {
    out_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
    if (!out_) throw Error("write_state: the stream failed (disk full or closed?)");
  }
  void u64(std::uint64_t v) { raw(&v, sizeof v); }
  void f64(double v) { raw(&v, sizeof v); }
  void vector(const Eigen::VectorXd& v) {
    u64(static_cast<std::uint64_t>(v.size()));
    raw(v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  }
  template <class M>
  void matrix(const M& m) {
    u64(static_cast<std::uint64_t>(m.rows()));
    u64(static_cast<std::uint64_t>(m.cols()));
    raw(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  }
  void string(const std::string& s) {
    u64(s.size());
    raw(s.data(), s.size());
  }

 private:
  std::ostream& out_;
};

class Reader {
 public:
  explicit Reader(std::istream& in) : in_(in) {}
  void raw(void* p, std::size_t n, const char* what) {
    in_.read(static_cast<char*>(p), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in_.gcount()) != n) {
      throw Error(std::string("read_state: truncated state (the stream ended while reading ") +
                  what + ")");
    }
  }
  std::uint64_t u64(const char* what) {
    std::uint64_t v = 0;
    raw(&v, sizeof v, what);
    return v;
  }
  std::uint64_t length(const char* what) {
    const std::uint64_t n = u64(what);
    if (n > kMaxLength) {
      throw Error(std::string("read_state: implausible length ") + std::to_string(n) + " of " +
                  what + " (damaged file?)");
    }
    return n;
  }
  double f64(const char* what) {
    double v = 0;
    raw(&v, sizeof v, what);
    return v;
  }
  void vector(Eigen::VectorXd& v, const char* what) {
    v.resize(static_cast<Eigen::Index>(length(what)));
    raw(v.data(), sizeof(double) * static_cast<std::size_t>(v.size()), what);
  }
  template <class M>
  void matrix(M& m, const char* what) {
    const auto rows = static_cast<Eigen::Index>(length(what));
    const auto cols = static_cast<Eigen::Index>(length(what));
    if (M::ColsAtCompileTime != Eigen::Dynamic && cols != M::ColsAtCompileTime) {
      throw Error(std::string("read_state: ") + what + " has " + std::to_string(cols) +
                  " columns, expected " + std::to_string(M::ColsAtCompileTime));
    }
    m.resize(rows, cols);
    raw(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()), what);
  }
  std::string string(const char* what) {
    std::string s(length(what), '\0');
    raw(s.data(), s.size(), what);
    return s;
  }

 private:
  std::istream& in_;
};

}  // namespace

void write_state(std::ostream& out, const SolverState& s) {
  Writer w(out);
  w.raw(kMagic, sizeof kMagic);
  const std::uint32_t version = kStateFormatVersion;
  w.raw(&version, sizeof version);
  w.f64(s.time);
  w.u64(s.steps);
  w.vector(s.displacement);
  w.vector(s.velocity);
  w.vector(s.acceleration);
  w.vector(s.external_force);
  w.u64(s.acceleration_valid ? 1 : 0);
  w.f64(s.external_work);
  w.f64(s.damping_work);
  w.u64(s.material_state.size());
  w.raw(s.material_state.data(), sizeof(double) * s.material_state.size());
  w.vector(s.coupling_force);
  w.u64(s.face_tractions.size());
  for (const auto& [face, t] : s.face_tractions) {
    w.string(face);
    w.matrix(t);
  }
  w.u64(s.nodal_force_nodes.size());
  for (auto n : s.nodal_force_nodes) w.u64(n);
  w.matrix(s.nodal_forces);
  w.f64(s.factor_dt);
  out.flush();
  if (!out) throw Error("write_state: the stream failed while flushing");
}

SolverState read_state(std::istream& in) {
  Reader r(in);
  char magic[sizeof kMagic];
  r.raw(magic, sizeof magic, "the magic number");
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) {
    throw Error("read_state: not a partita FEM state (wrong magic number; expected 'PFEMSTAT')");
  }
  std::uint32_t version = 0;
  r.raw(&version, sizeof version, "the format version");
  if (version != kStateFormatVersion) {
    throw Error("read_state: state format version " + std::to_string(version) +
                " is not supported (this build reads version " +
                std::to_string(kStateFormatVersion) + ")");
  }
  SolverState s;
  s.time = r.f64("time");
  s.steps = r.u64("steps");
  r.vector(s.displacement, "displacement");
  r.vector(s.velocity, "velocity");
  r.vector(s.acceleration, "acceleration");
  r.vector(s.external_force, "external force");
  s.acceleration_valid = r.u64("flags") != 0;
  s.external_work = r.f64("external work");
  s.damping_work = r.f64("damping work");
  s.material_state.resize(r.length("material state"));
  r.raw(s.material_state.data(), sizeof(double) * s.material_state.size(), "material state");
  r.vector(s.coupling_force, "coupling force");
  const std::uint64_t faces = r.length("face tractions");
  for (std::uint64_t i = 0; i < faces; ++i) {
    std::string face = r.string("a face name");
    r.matrix(s.face_tractions[face], "face tractions");
  }
  s.nodal_force_nodes.resize(r.length("nodal force nodes"));
  for (auto& n : s.nodal_force_nodes) n = r.u64("nodal force nodes");
  r.matrix(s.nodal_forces, "nodal forces");
  s.factor_dt = r.f64("the factorised step size");
  return s;
}

}  // namespace partita::fem
