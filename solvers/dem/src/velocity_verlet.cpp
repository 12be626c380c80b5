// VelocityVerlet: loading the packed state from the particle store and mirroring it back.
#include "partita/dem/velocity_verlet.hpp"

#include "parallel_pass.hpp"

#include <cstddef>

namespace partita::dem {

void VelocityVerlet::load(const Particles& p) {
  const int n = static_cast<int>(p.size());
  packed_.resize(n);
  detail::parallel_pass(n, [&](int i) {
    PackedParticle& q = packed_[i];
    q.x = p.position[i], q.v = p.velocity[i], q.w = p.angular_velocity[i];
    q.r = p.radius[i], q.f = p.force[i], q.t = p.torque[i];
  });
  loaded_ = true;
  mirror_current_ = true;
  has_motion_ = false;
}

// (in parallel for large beds: a serial pass over 10^6 particles, once a coupling window, would
// limit the thread scaling of the parallel steps around it)
void VelocityVerlet::copy_back(Particles& p) const {
  detail::parallel_pass(static_cast<std::ptrdiff_t>(packed_.size()), [&](std::ptrdiff_t i) {
    p.position[i] = packed_[i].x;
    p.velocity[i] = packed_[i].v;
    p.angular_velocity[i] = packed_[i].w;
    p.force[i] = packed_[i].f;
    p.torque[i] = packed_[i].t;
  });
  mirror_current_ = true;
}

}  // namespace partita::dem
