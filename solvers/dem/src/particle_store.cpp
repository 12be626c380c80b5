#include "partita/dem/particle_store.hpp"

namespace partita::dem {

ParticleStore::ParticleStore() {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  add_core("position", &Particles::position, zero);
  add_core("velocity", &Particles::velocity, zero);
  add_core("angular_velocity", &Particles::angular_velocity, zero);
  add_core("force", &Particles::force, zero);
  add_core("torque", &Particles::torque, zero);
  add_core("radius", &Particles::radius, 0.0);
  add_core("mass", &Particles::mass, 0.0);
  add_core("inertia", &Particles::inertia, 0.0);
  add_core("material", &Particles::material, 0);
  add_core("id", &Particles::id, std::int64_t{-1});
}

ParticleStore::ParticleStore(const ParticleStore& other)
    : core_(other.core_), next_id_(other.next_id_) {
  for (const auto& c : other.columns_) columns_.push_back(c->clone());
}

ParticleStore& ParticleStore::operator=(const ParticleStore& other) {
  if (this == &other) return *this;
  core_ = other.core_;
  next_id_ = other.next_id_;
  columns_.clear();
  for (const auto& c : other.columns_) columns_.push_back(c->clone());
  return *this;
}

int ParticleStore::find(const std::string& name) const {
  for (std::size_t k = 0; k < columns_.size(); ++k)
    if (columns_[k]->name == name) return static_cast<int>(k);
  return -1;
}

void ParticleStore::set_width(int handle, std::size_t width) {
  if (columns_[handle]->width != width) columns_[handle]->set_width(core_, width);
}

void ParticleStore::reserve(std::size_t n) {
  for (auto& c : columns_) c->reserve(core_, n);
}

void ParticleStore::shrink_to_fit() {
  for (auto& c : columns_) c->shrink(core_);
  scratch_.clear();
  scratch_.shrink_to_fit();
}

std::size_t ParticleStore::add(std::int64_t id) {
  const std::size_t index = size();
  for (auto& c : columns_) c->resize(core_, index + 1);
  if (id < 0) id = next_id_;
  core_.id[index] = id;
  next_id_ = std::max(next_id_, id + 1);
  return index;
}

void ParticleStore::remove(const std::vector<char>& flag, std::vector<int>& new_of_old) {
  const std::size_t n = size();
  if (flag.size() != n)
    throw Error("particle store: remove() needs one flag per particle, got " +
                std::to_string(flag.size()) + " for " + std::to_string(n));
  new_of_old.resize(n);
  int k = 0;
  for (std::size_t i = 0; i < n; ++i) new_of_old[i] = flag[i] ? -1 : k++;
  for (auto& c : columns_) c->compact(core_, new_of_old, static_cast<std::size_t>(k));
}

void ParticleStore::permute(const std::vector<int>& order) {
  if (order.size() != size())
    throw Error("particle store: permute() needs one index per particle, got " +
                std::to_string(order.size()) + " for " + std::to_string(size()));
  std::size_t entry = 1;
  for (const auto& c : columns_) entry = std::max(entry, c->element_size());
  const std::size_t words = (order.size() * entry + sizeof(std::max_align_t) - 1) /
                            sizeof(std::max_align_t);
  if (scratch_.size() < words) scratch_.resize(words);  // (kept: no allocation next time)
  for (auto& c : columns_) c->permute(core_, order, scratch_.data());
}

void ParticleStore::write(BinaryWriter& out) const {
  out.value(static_cast<std::uint64_t>(size()));
  out.value(next_id_);
  out.value(static_cast<std::uint64_t>(columns_.size()));
  for (const auto& c : columns_) c->write(core_, out);
}

void ParticleStore::read(BinaryReader& in) {
  const auto n = in.value<std::uint64_t>("particle count");
  in.value(next_id_, "next particle id");
  in.expect(static_cast<std::uint64_t>(columns_.size()), "number of particle arrays");
  for (auto& c : columns_) {
    c->read(core_, in);
    if (c->length(core_) != n * c->width)
      throw Error("corrupt state: particle array '" + c->name + "' has " +
                  std::to_string(c->length(core_)) + " entries for " + std::to_string(n) +
                  " particles of width " + std::to_string(c->width));
  }
}

std::size_t ParticleStore::packed_bytes_per_particle() const {
  std::size_t bytes = 0;
  for (const auto& c : columns_) bytes += c->width * c->element_size();
  return bytes;
}

void ParticleStore::pack(const std::vector<int>& which, std::vector<std::byte>& out) const {
  const std::size_t n = size();
  for (const int i : which)
    if (i < 0 || static_cast<std::size_t>(i) >= n)
      throw Error("particle store: pack() of particle " + std::to_string(i) + " of " +
                  std::to_string(n));
  std::size_t at = out.size();
  out.resize(at + which.size() * packed_bytes_per_particle());
  for (const auto& c : columns_) {
    c->pack(core_, which, out.data() + at);
    at += which.size() * c->width * c->element_size();
  }
}

namespace {

std::size_t whole_particles(std::size_t bytes, std::size_t row) {
  if (row == 0 || bytes % row != 0)
    throw Error("particle store: unpack() of " + std::to_string(bytes) +
                " bytes, not a whole number of particles of " + std::to_string(row) +
                " bytes (packed by a store of another layout?)");
  return bytes / row;
}

}  // namespace

void ParticleStore::packed_ids(const std::byte* data, std::size_t bytes,
                               std::vector<std::int64_t>& ids) const {
  const std::size_t n = whole_particles(bytes, packed_bytes_per_particle());
  ids.resize(n);
  for (const auto& c : columns_) {
    if (c->name == "id" && c->type() == typeid(std::int64_t) && c->width == 1) {
      if (n > 0) std::memcpy(ids.data(), data, n * sizeof(std::int64_t));
      return;
    }
    data += n * c->width * c->element_size();
  }
}

std::size_t ParticleStore::unpack(const std::byte* data, std::size_t bytes) {
  const std::size_t first = size();
  const std::size_t n = whole_particles(bytes, packed_bytes_per_particle());
  for (auto& c : columns_) {
    c->unpack(core_, n, data);
    data += n * c->width * c->element_size();
  }
  std::int64_t next = next_id_;
  for (std::size_t i = first; i < first + n; ++i) {
    if (core_.id[i] < 0) {
      const std::int64_t bad = core_.id[i];
      for (auto& c : columns_) c->resize(core_, first);  // the store as it was
      throw Error("particle store: unpack() found particle id " + std::to_string(bad) +
                  " (ids are >= 0: packed by a store of another layout?)");
    }
    next = std::max(next, core_.id[i] + 1);
  }
  next_id_ = next;
  return first;
}

std::string ParticleStore::layout() const {
  std::string s;
  for (const auto& c : columns_)
    s += c->name + ":" + std::to_string(c->width) + "x" + std::to_string(c->element_size()) + ";";
  return s;
}

std::uint64_t ParticleStore::layout_hash() const {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a, 64 bits
  const auto mix = [&h](const void* data, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < n; ++k) h = (h ^ b[k]) * 0x100000001b3ull;
  };
  for (const auto& c : columns_) {
    mix(c->name.data(), c->name.size());
    const std::uint64_t sizes[3] = {c->name.size(), c->width, c->element_size()};
    mix(sizes, sizeof sizes);
  }
  return h;
}

}  // namespace partita::dem
