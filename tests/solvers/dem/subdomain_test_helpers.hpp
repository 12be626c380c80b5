#pragma once
// Shared pieces of the split-bed tests (SubdomainStepper): a polydisperse bed thrown about, a
// transport that rewrites the particle messages of a list build on their way (to show what the
// bits need: take something out, and the split must differ), the owned particles' positions (for
// a re-cut) and the comparison of particle states by id; the beds are subdomain_beds.hpp's.

#include "subdomain_beds.hpp"

#include "partita/dem/subdomain.hpp"
#include "partita/dem/subdomain_transport.hpp"

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace partita::dem::test {

template <class T>
T read_at(const std::byte* at) {
  T v;
  std::memcpy(&v, at, sizeof v);
  return v;
}

/// Passes every exchange on to `inner`, with each System::pack_particles() message inside the
/// "PSDM" frames of a list build (subdomain.hpp: magic, version, the migrants' and the ghosts'
/// message sizes, then the two messages) replaced by rewrite(message, bytes).
class RewritingTransport final : public SubdomainTransport {
 public:
  using Rewrite =
      std::function<std::vector<std::byte>(const std::byte* message, std::size_t bytes)>;
  RewritingTransport(SubdomainTransport& inner, Rewrite rewrite)
      : inner_(inner), rewrite_(std::move(rewrite)) {}
  int parts() const override { return inner_.parts(); }
  const std::vector<int>& local() const override { return inner_.local(); }
  double max(const std::vector<double>& values) override { return inner_.max(values); }
  void exchange(std::vector<SubdomainMail>& out, std::vector<SubdomainMail>& in) override {
    for (SubdomainMail& mail : out)
      for (std::vector<std::byte>& m : mail)
        if (m.size() >= 24 && read_at<std::uint32_t>(m.data()) == 0x4d445350u) m = frame(m);
    inner_.exchange(out, in);
  }

 private:
  std::vector<std::byte> frame(const std::vector<std::byte>& m) const {
    const auto a = read_at<std::uint64_t>(m.data() + 8), b = read_at<std::uint64_t>(m.data() + 16);
    std::vector<std::byte> out(m.begin(), m.begin() + 24);
    std::vector<std::byte> ma, mb;
    if (a > 0) ma = rewrite_(m.data() + 24, a);
    if (b > 0) mb = rewrite_(m.data() + 24 + a, b);
    const std::uint64_t sa = ma.size(), sb = mb.size();
    std::memcpy(out.data() + 8, &sa, 8);
    std::memcpy(out.data() + 16, &sb, 8);
    out.insert(out.end(), ma.begin(), ma.end());
    out.insert(out.end(), mb.begin(), mb.end());
    return out;
  }
  SubdomainTransport& inner_;
  Rewrite rewrite_;
};

/// One System a subdomain (make(k) for subdomain k) and the pointers a SubdomainStepper takes.
struct SplitSystems {
  std::vector<std::unique_ptr<System>> systems;
  std::vector<System*> raw;
};
template <class Make>
SplitSystems make_systems(int parts, Make&& make) {
  SplitSystems s;
  for (int k = 0; k < parts; ++k) {
    s.systems.push_back(make(k));
    s.raw.push_back(s.systems.back().get());
  }
  return s;
}

/// The positions of the particles the local subdomains own (for a re-cut by bisection).
inline std::vector<Eigen::Vector3d> owned_positions(const SubdomainStepper& stepper) {
  std::vector<Eigen::Vector3d> x;
  for (int k = 0; k < stepper.local_count(); ++k) {
    const Subdomain& sd = stepper.subdomain(k);
    const Particles& p = sd.system().particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!sd.is_ghost(i)) x.push_back(p.position[i]);
  }
  return x;
}

/// A particle's motion at the end of a run, and the owned particles of a split by id.
struct MotionState {
  Eigen::Vector3d x, v, w;
};
using MotionById = std::map<std::int64_t, MotionState>;

/// How many particles differ from the reference in any bit of x, v or omega, or are missing.
inline std::size_t differing(const MotionById& a, const MotionById& ref) {
  REQUIRE(a.size() == ref.size());
  std::size_t n = 0;
  for (const auto& [id, s] : ref) {
    const auto it = a.find(id);
    n += it == a.end() || it->second.x != s.x || it->second.v != s.v || it->second.w != s.w ? 1 : 0;
  }
  return n;
}

}  // namespace partita::dem::test
