#pragma once
// One store for every per-particle array (as LAMMPS atom styles do with grow/copy/pack): the
// core quantities of Particles and any array a component registers (contact histories with
// walls and meshes, a breakage model's strengths, ...). Each array is registered once with its
// width (entries per particle) and the value a new particle gets; from then on adding, removing,
// permuting, copying, writing and reading particles treats all of them together, so no
// component keeps a parallel array that could fall out of step.
//
// Ids: every particle has a stable 64-bit id (Particles::id) that survives renumbering, removal
// and restart. add() takes the caller's id or, given a negative one, the next free id (one more
// than the largest id ever held, so an id is never reused within a run).
//
// Memory: each array holds exactly its particles' entries (add_particles() reserves the final
// size; growth one particle at a time is geometric, one array at a time). permute() gathers one
// entry column at a time (entry j of every particle of one array) into a scratch of one entry per
// particle, in parallel on large stores, and copies it back: no second copy of any array, and
// independent reads that the processor overlaps (an in-place walk along the permutation's cycles
// waits for each read in turn: 0.29-0.31 s for the scale case's 10^6 granules on 2 threads,
// against 0.087-0.094 s). remove() compacts in place. The scratch (the largest entry size per
// particle: 24 B for a Vector3d) is kept between calls, so neither allocates once the store has
// had its largest size.

#include "partita/dem/binary_reader.hpp"
#include "partita/dem/binary_writer.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/particles.hpp"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <vector>

namespace partita::dem {

class ParticleStore {
 public:
  ParticleStore();
  ParticleStore(const ParticleStore& other);
  ParticleStore& operator=(const ParticleStore& other);
  ParticleStore(ParticleStore&&) noexcept = default;
  ParticleStore& operator=(ParticleStore&&) noexcept = default;

  /// Registers an array of `width` entries of T per particle, filled with `fill` for the particles
  /// there are and for every particle added later; returns its handle. Names are unique.
  template <class T>
  int add_array(const std::string& name, std::size_t width, const T& fill);
  /// Handle of the array `name`, or -1.
  int find(const std::string& name) const;
  template <class T>
  std::vector<T>& array(int handle);
  template <class T>
  const std::vector<T>& array(int handle) const;
  std::size_t width(int handle) const { return columns_[handle]->width; }
  /// Changes an array's width, keeping each particle's first min(old, new) entries and filling
  /// the rest (e.g. a history per wall plane when a plane is added).
  void set_width(int handle, std::size_t width);
  int array_count() const { return static_cast<int>(columns_.size()); }
  const std::string& array_name(int handle) const { return columns_[handle]->name; }

  Particles& core() { return core_; }
  const Particles& core() const { return core_; }
  std::size_t size() const { return core_.size(); }
  void reserve(std::size_t n);
  /// Gives back the memory the arrays hold beyond their particles (after a large removal: a
  /// split bed's rank keeping its share of the bed it was built with).
  void shrink_to_fit();

  /// Appends one particle: every array grows by its fill values; the id is `id`, or the next free
  /// id when id < 0. Returns the new index; the caller sets the core values.
  std::size_t add(std::int64_t id = -1);
  /// Removes the particles with remove[i] != 0, keeping the order of the others; new_of_old[i]
  /// becomes the new index of old particle i, or -1.
  void remove(const std::vector<char>& remove, std::vector<int>& new_of_old);
  /// Renumbers: new particle k is old particle order[k] (order is a permutation).
  void permute(const std::vector<int>& order);
  /// The id the next add() without an id gets.
  std::int64_t next_id() const { return next_id_; }
  /// Raises next_id() to at least `next` (ids given out elsewhere: a split bed's subdomains).
  void reserve_ids(std::int64_t next) { next_id_ = next > next_id_ ? next : next_id_; }

  /// Writes / reads every array (names, widths and contents) and the id counter. read() requires
  /// the same arrays (names, element sizes) in the same order; it throws Error otherwise.
  void write(BinaryWriter& out) const;
  void read(BinaryReader& in);

  /// Particles as bytes, to move them between stores of the same layout (another process's
  /// subdomain, a buffer for later): pack() appends to `out` every array's entries of the
  /// particles `which`, in that order (array by array, each array's rows of those particles one
  /// after the other: width x element size bytes a row), ids included; unpack() appends the
  /// particles of such a buffer to this store, in the same order, with their ids, and raises the
  /// next free id above them. Both stores must have the same arrays (names, element types and
  /// widths, in the same order): layout() says what that is, and unpack() throws Error when the
  /// buffer's size is not a whole number of particles of this layout. The bytes are the
  /// elements' own (the state file's assumption: both ends have the same byte order and types).
  /// Neither allocates beyond `out` growing and the arrays growing to their new size.
  std::size_t packed_bytes_per_particle() const;
  void pack(const std::vector<int>& which, std::vector<std::byte>& out) const;
  /// Returns the index of the first unpacked particle (the store's former size).
  std::size_t unpack(const std::byte* data, std::size_t bytes);
  /// The ids of the particles in such a buffer, in order, into `ids` (cleared first), without
  /// changing the store: to check a buffer before unpack(). Throws Error as unpack() does when
  /// the size is not a whole number of particles.
  void packed_ids(const std::byte* data, std::size_t bytes, std::vector<std::int64_t>& ids) const;
  /// The arrays' names, widths and element sizes, as text (equal on two stores = packed
  /// particles move between them).
  std::string layout() const;
  /// A 64-bit hash (FNV-1a) of what layout() says, computed without allocating: for a message's
  /// header, so that a receiver refuses particles packed by a store of another layout.
  std::uint64_t layout_hash() const;

 private:
  struct Column {
    std::string name;
    std::size_t width = 1;
    virtual ~Column() = default;
    virtual std::unique_ptr<Column> clone() const = 0;
    virtual std::size_t element_size() const = 0;
    virtual const std::type_info& type() const = 0;
    virtual std::size_t length(const Particles& core) const = 0;
    virtual void resize(Particles& core, std::size_t n) = 0;
    virtual void reserve(Particles& core, std::size_t n) = 0;
    virtual void shrink(Particles& core) = 0;
    virtual void compact(Particles& core, const std::vector<int>& new_of_old, std::size_t n) = 0;
    // scratch: room for one entry per particle (element_size() bytes each, max_align_t aligned)
    virtual void permute(Particles& core, const std::vector<int>& order,
                         std::max_align_t* scratch) = 0;
    virtual void set_width(Particles& core, std::size_t width) = 0;
    virtual void write(const Particles& core, BinaryWriter& out) const = 0;
    virtual void read(Particles& core, BinaryReader& in) = 0;
    // the rows of particles `which` as bytes at `out` (which.size() x width x element_size())
    virtual void pack(const Particles& core, const std::vector<int>& which,
                      std::byte* out) const = 0;
    // appends n rows read from `in` (as pack() wrote them)
    virtual void unpack(Particles& core, std::size_t n, const std::byte* in) = 0;
  };
  template <class T>
  struct TypedColumn;

  template <class T>
  void add_core(const char* name, std::vector<T> Particles::*member, const T& fill);

  Particles core_;
  std::vector<std::unique_ptr<Column>> columns_;
  std::int64_t next_id_ = 0;
  std::vector<std::max_align_t> scratch_;  // of permute(): one entry per particle
};

// ---- implementation of the typed arrays ------------------------------------------------------

template <class T>
struct ParticleStore::TypedColumn final : Column {
  std::vector<T> own;                           // the data, unless it is a core array
  std::vector<T> Particles::*member = nullptr;  // the core array it stands for
  T fill{};

  std::vector<T>& data(Particles& core) { return member ? core.*member : own; }
  const std::vector<T>& data(const Particles& core) const { return member ? core.*member : own; }

  std::unique_ptr<Column> clone() const override {
    auto c = std::make_unique<TypedColumn<T>>();
    c->name = name, c->width = width, c->own = own, c->member = member, c->fill = fill;
    return c;
  }
  std::size_t element_size() const override { return sizeof(T); }
  const std::type_info& type() const override { return typeid(T); }
  std::size_t length(const Particles& core) const override { return data(core).size(); }
  void resize(Particles& core, std::size_t n) override { data(core).resize(n * width, fill); }
  void reserve(Particles& core, std::size_t n) override { data(core).reserve(n * width); }
  void shrink(Particles& core) override { data(core).shrink_to_fit(); }
  void compact(Particles& core, const std::vector<int>& new_of_old, std::size_t n) override {
    std::vector<T>& v = data(core);
    for (std::size_t i = 0; i < new_of_old.size(); ++i) {
      const int k = new_of_old[i];
      if (k < 0 || static_cast<std::size_t>(k) == i) continue;
      std::copy_n(v.begin() + i * width, width, v.begin() + static_cast<std::size_t>(k) * width);
    }
    v.resize(n * width);
  }
  // new row k = old row order[k]: entry column by entry column, gathered into the scratch (in
  // parallel: independent reads), then copied back
  void permute(Particles& core, const std::vector<int>& order,
               std::max_align_t* scratch) override {
    static_assert(alignof(T) <= alignof(std::max_align_t));
    std::vector<T>& v = data(core);
    const auto n = static_cast<std::ptrdiff_t>(order.size());
    const auto w = static_cast<std::ptrdiff_t>(width);
    T* const tmp = reinterpret_cast<T*>(scratch);
    T* const d = v.data();
    const int* const o = order.data();
    for (std::ptrdiff_t j = 0; j < w; ++j) {
#pragma omp parallel for schedule(static) if (n >= 16384)
      for (std::ptrdiff_t k = 0; k < n; ++k) new (tmp + k) T(d[o[k] * w + j]);
#pragma omp parallel for schedule(static) if (n >= 16384)
      for (std::ptrdiff_t k = 0; k < n; ++k) {
        d[k * w + j] = tmp[k];
        tmp[k].~T();
      }
    }
  }
  void set_width(Particles& core, std::size_t w) override {
    std::vector<T>& v = data(core);
    const std::size_t n = width > 0 ? v.size() / width : core.size();
    std::vector<T> next(n * w, fill);
    for (std::size_t i = 0; i < n; ++i)
      std::copy_n(v.begin() + i * width, std::min(width, w), next.begin() + i * w);
    v.swap(next);
    width = w;
  }
  void write(const Particles& core, BinaryWriter& out) const override {
    out.string(name);
    out.value(static_cast<std::uint64_t>(width));
    out.value(static_cast<std::uint64_t>(sizeof(T)));
    out.array(data(core));
  }
  void pack(const Particles& core, const std::vector<int>& which,
            std::byte* out) const override {
    static_assert(std::is_standard_layout_v<T>, "raw bytes need a standard-layout type");
    const std::vector<T>& v = data(core);
    const std::size_t row = width * sizeof(T);
    for (const int i : which) {
      if (row > 0) std::memcpy(out, v.data() + static_cast<std::size_t>(i) * width, row);
      out += row;
    }
  }
  void unpack(Particles& core, std::size_t n, const std::byte* in) override {
    std::vector<T>& v = data(core);
    const std::size_t first = v.size();
    v.resize(first + n * width);
    // (through a byte pointer: T is standard layout and trivially copyable in its bytes, e.g.
    // Eigen::Vector3d, whose non-trivial copy-assignment -Wclass-memaccess would flag)
    if (n * width > 0)
      std::memcpy(static_cast<void*>(v.data() + first), in, n * width * sizeof(T));
  }
  void read(Particles& core, BinaryReader& in) override {
    const std::string found = in.string("a particle array name");
    if (found != name)
      throw Error("state does not fit this system: particle array '" + found +
                  "' in the state where this system has '" + name + "'");
    width = in.value<std::uint64_t>("particle array width");
    in.expect(static_cast<std::uint64_t>(sizeof(T)), "particle array element size");
    in.array(data(core), name.c_str());
  }
};

template <class T>
void ParticleStore::add_core(const char* name, std::vector<T> Particles::*member, const T& fill) {
  auto c = std::make_unique<TypedColumn<T>>();
  c->name = name, c->member = member, c->fill = fill;
  columns_.push_back(std::move(c));
}

template <class T>
int ParticleStore::add_array(const std::string& name, std::size_t width, const T& fill) {
  if (find(name) >= 0) throw Error("particle store: an array named '" + name + "' exists already");
  auto c = std::make_unique<TypedColumn<T>>();
  c->name = name, c->width = width, c->fill = fill;
  c->own.assign(size() * width, fill);
  columns_.push_back(std::move(c));
  return static_cast<int>(columns_.size()) - 1;
}

template <class T>
std::vector<T>& ParticleStore::array(int handle) {
  Column& c = *columns_[handle];
  if (c.type() != typeid(T))
    throw Error("particle store: array '" + c.name + "' read with another element type");
  return static_cast<TypedColumn<T>&>(c).data(core_);
}

template <class T>
const std::vector<T>& ParticleStore::array(int handle) const {
  const Column& c = *columns_[handle];
  if (c.type() != typeid(T))
    throw Error("particle store: array '" + c.name + "' read with another element type");
  return static_cast<const TypedColumn<T>&>(c).data(core_);
}

}  // namespace partita::dem
