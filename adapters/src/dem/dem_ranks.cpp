// The DEM adapter on several ranks (SolverContext::ranks): `mpirun -n N partita run CASE` for a
// case whose one participant is a DEM, or the DEM participant of a coupled case on the N processes
// that follow its --participant (mpirun -n 1 partita run CASE --participant plate : -n N partita
// run CASE --participant granules).
//
// The bed is split into N subdomains, one a rank (dem::SubdomainStepper over
// dem::MpiSubdomainTransport; subdomain.hpp says why the split steps to the same bits on any N):
// every rank builds the participant alike from the case (materials, walls, meshes and every
// particle, generated or read), keeps the particles that its box of a bisection of the starting
// positions owns, and steps them; the bed is cut again as the load drifts (ranks_rebalance()).
// The decomposition's bounds are the domain's box (walls, meshes,
// particles at the start) grown by 2 R_max + skin on every side, the same on every N: the global
// order's grid, and so every sum, does not depend on N. The skin is the case's, or 10 % of the
// largest radius (as one System's default). The cut waits for the meshes taken from another
// participant (meshes: [{from: ...}]): they widen the domain (ranks_split()).
//
// Rank 0 leads: the run (in one process, or the server a controller talks to) drives its adapter
// through the Solver contract, and the adapter tells the others what to do (a command, through
// the transport) before doing it with them:
//   mesh             (set-up) a mesh taken from another participant, which the leader received:
//                    every rank adds it alike (its one_sided flag from the case, as the leader's);
//   advance dt       every rank steps its subdomain (walls moved by their tables alike);
//   monitors groups  the sums the quantities asked for need, each an exact sum over the owned
//                    particles rounded once (SubdomainStepper: kinetic energy, momentum, elastic
//                    energy, each wall's, box face's and mesh's force, the contacts, the energy
//                    books and their balance), the monitor
//                    particles' states gathered from their owners: the same bits on any N;
//   check            every rank's astray owned particle of lowest id to rank 0, and a stop
//                    signal that reached another rank's process alone (rank 0 then stops the
//                    run after the window, as for its own: ParticipantRanks::raise_stop());
//   output frame     every rank writes its owned particles as one piece
//                    (<prefix>_particles_<frame>_<rank>.vtp), rank 0 the .pvtp that joins them
//                    (the series' file: ParaView opens the pieces as one) and the meshes with the
//                    forces summed over the ranks;
//   restart          dem::SplitRestart gathered to rank 0 (one stream, resumed on any number of
//                    ranks);
//   resume stream    every rank restores it (rank 0 takes the particles, the first list build
//                    sends each to its owner) and checks its particles;
//   particles file   (output.particles_file, at finalize(); every-output: with each frame) every
//                    owned particle to rank 0, which writes them in the order of their ids (the
//                    same file on any N);
//   read             coupled data read: a mesh's displacement (every rank's System holds every
//                    mesh whole and moves it alike) or its triangles' `attached` states (sent only
//                    when they change); no message of its own: the leader applies it at once and
//                    passes it on ahead of its next command, in the same message;
//   write            coupled data written: the forces on a mesh's vertices or triangles (or the
//                    tractions f / A) from SubdomainStepper's exact sums over the owned particles'
//                    contacts, rounded once: the same bits on any N. After each step the vertex
//                    forces of a mesh that a displacement moved are summed alike for the
//                    interface-work audit (kept by the leader), so interface_work() is the same
//                    bits on any N too;
//   restore stream   (restore_checkpoint(): an implicit scheme's next iteration) the split bed that
//                    save_checkpoint() gathered (a restart stream, `restart` above) resumed on
//                    every rank, as a restart file is: the same bits on any N;
//   finish / end     the others' loop ends (finalize(): status 0; a failure on rank 0: the
//                    status the app gives, end_others()).
// The others run follow() (the loop the adapter claims the ranks with) until finish or end.
//
// Wall servos: the adapter applies dem::WallServo's law after each step with the wall's force
// summed over the ranks (the hook on each rank's System would steer by that rank's part).
//
// The energy accounting (energy_accounting: true) keeps the split's books (SubdomainStepper::
// set_energy_accounting(): each step's terms of the owned particles in exact sums, the same bits
// on any N; they travel in the restart stream); its monitors come with `monitors groups`.
//
// Breakage: each rank breaks the particles it owns, the stepper numbers the fragments over the
// ranks and builds the ghosts and lists again (subdomain.hpp), so the set and every sum are the
// same on any N; the counters are exact sums over the ranks (monitors group kBreakage), the
// stable step the smallest over the ranks (a step that fragments made too long is split, as in
// one process), the particle count and mass summed again after each change, the grading of an
// output frame from every rank's particles (gathered to rank 0 in the order of their ids).
// `breakage.lists: local` has no effect on ranks (the split builds its lists after a change).
//
// Not handled on a split yet: at run time a monitor quantity not listed above (none of the DEM's
// today: a guard for new ones).
//
// The split path gives the same bytes on every N, N = 1 under mpirun (or --on-ranks) included. It
// is not the path of one process without mpirun (one dem::System stepped whole): the split numbers
// the particles by a global grid and sums forces on walls and meshes in exact sums, so the two
// differ in the last bits, and so do their monitors (README, "A DEM-only case on N ranks").
//
// A failure: on rank 0 before a command (a refused quantity, a file it cannot write) the app ends
// the others with end_others(); during a command on any rank (or a rank that does not answer
// within the deadline) the ranks are marked broken and the app ends them all (MPI_Abort) after
// the message.

#include "dem_ranks.hpp"
#include "dem_adapter.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cstring>
#include <limits>
#include <sstream>

#include "partita/adapters/dem_output.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/dem/breakage.hpp"
#include "partita/dem/error.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/registry.hpp"

#ifdef PARTITA_DEM_MPI
#include <mpi.h>

#include "partita/dem/mpi_transport.hpp"
#endif

namespace partita::adapters {

namespace {

using config::Node;

enum class Command : std::uint32_t {
  advance = 1,
  monitors,
  check,
  output,
  restart,
  resume,
  finish,
  end,
  particles_file,
  restore,  // a checkpoint's split bed resumed (an implicit scheme's next iteration)
  mesh,     // a mesh taken from another participant: name, points, triangles
  read,     // coupled data read: mesh index, what (OnRanks::kDisplacement, kAttached), values
  write     // coupled data written: mesh index, what (OnRanks::kVertexForce, ...)
};

// the monitor groups (what ranks_monitors() sums)
// the load's check (ranks_rebalance())
constexpr long kBalanceEvery = 200;
constexpr double kImbalance = 1.25;

constexpr std::uint32_t kKinetic = 1, kElastic = 2, kWalls = 4, kMeshes = 8, kTracked = 16,
                        kFaceGroup = 32, kContacts = 64, kEnergy = 128, kBreakage = 256;

// the breakage counters' monitor quantities
const char* const kBreakageNames[] = {
    "breakage.events",          "breakage.fragments",     "breakage.fragment_mass",
    "breakage.mass_lost",       "breakage.mass_restored", "breakage.energy_released",
    "breakage.powder_events",   "breakage.powder_mass",   "breakage.powder_energy"};

// the energy accounting's monitor quantities (besides <wall>.work and <mesh>.work)
const char* const kEnergyNames[] = {"friction_work",   "damping_work", "breakage_energy",
                                    "stiffening_work", "gravity_work", "wall_work",
                                    "energy_balance_error"};

// A message's bytes.
class Bytes {
 public:
  explicit Bytes(Command c) { put(static_cast<std::uint32_t>(c)); }
  Bytes() = default;
  template <class T>
  Bytes& put(const T& v) {
    const std::size_t at = b_.size();
    b_.resize(at + sizeof v);
    std::memcpy(b_.data() + at, &v, sizeof v);
    return *this;
  }
  Bytes& put(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    const std::size_t at = b_.size();
    b_.resize(at + s.size());
    if (!s.empty()) std::memcpy(b_.data() + at, s.data(), s.size());
    return *this;
  }
  /// rows (u64), cols (u64), then the values column by column (Eigen's storage)
  template <class M>
  Bytes& put_matrix(const M& m) {
    put(static_cast<std::uint64_t>(m.rows())).put(static_cast<std::uint64_t>(m.cols()));
    const std::size_t n = static_cast<std::size_t>(m.size()) * sizeof(typename M::Scalar);
    const std::size_t at = b_.size();
    b_.resize(at + n);
    if (n) std::memcpy(b_.data() + at, m.data(), n);
    return *this;
  }
  std::vector<std::byte>& bytes() { return b_; }

 private:
  std::vector<std::byte> b_;
};

class Reader {
 public:
  explicit Reader(const std::vector<std::byte>& b) : b_(b) {}
  template <class T>
  T get() {
    T v{};
    need(sizeof v);
    std::memcpy(&v, b_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  std::string string() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(reinterpret_cast<const char*>(b_.data() + at_), n);
    at_ += n;
    return s;
  }
  template <class M>
  void matrix(M& m) {
    const auto rows = get<std::uint64_t>(), cols = get<std::uint64_t>();
    const std::size_t n = rows * cols * sizeof(typename M::Scalar);
    need(n);
    m.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    if (n) std::memcpy(m.data(), b_.data() + at_, n);
    at_ += n;
  }
  bool done() const { return at_ == b_.size(); }

 private:
  void need(std::size_t n) const {
    if (n > b_.size() - at_)
      throw Error("dem on ranks: a message from another rank ends early (" +
                  std::to_string(b_.size()) + " bytes)");
  }
  const std::vector<std::byte>& b_;
  std::size_t at_ = 0;
};

const char* const kComponents[] = {"x", "y", "z", "vx", "vy", "vz"};

}  // namespace

// ---- set-up ----------------------------------------------------------------------------------

void DemAdapter::setup_ranks(const SolverContext& context) {
  const std::shared_ptr<ParticipantRanks>& ranks = context.ranks;
  const Node& c = context.config;
  // the energy accounting: the split's books (SubdomainStepper), not the System's own (it keeps
  // them per System, and refuses a step taken in phases)
  const bool books = system_.energy_tracking();
  system_.set_energy_tracking(false);
#ifndef PARTITA_DEM_MPI
  throw Error("dem '" + name_ +
              "': this partita was built without the DEM's MPI transport "
              "(partita::dem_mpi): it cannot run on several ranks");
#else
  if (system_.particles().size() == 0)
    c["particles"].fail("a DEM on several ranks needs particles at the start");
  auto o = std::make_unique<OnRanks>();
  o->ranks = ranks;
  o->books = books;
  o->skin = c.has("skin") ? c.real("skin") : 0.0;
  try {
    const MPI_Comm comm = *static_cast<const MPI_Comm*>(ranks->communicator());
    o->transport = std::make_unique<dem::MpiSubdomainTransport>(comm, ranks->deadline());
  } catch (const dem::PeerTimeout& e) {
    ranks->set_broken();
    throw Error("dem '" + name_ + "' on rank " + std::to_string(ranks->rank()) + ": " + e.what());
  } catch (const dem::Error& e) {
    c.fail(std::string("DEM model of participant '") + name_ + "' on ranks: " + e.what());
  }
  const auto size = static_cast<std::size_t>(ranks->size());
  o->out.assign(1, dem::SubdomainMail(size));
  o->in.assign(1, dem::SubdomainMail(size));
  ranks_ = std::move(o);
  // the split waits for the meshes taken from other participants (they widen the domain, and
  // their materials may lower the stable step): the leader receives them at the run's set-up and
  // passes each on (Command::mesh), every rank adds it alike
  if (requests_.empty()) ranks_split();
  // (last: a constructor that throws leaves the handle unclaimed; ~DemAdapter() lets it go)
  if (ranks->leads())
    ranks->claim(nullptr, [this](int status) { end_others(status); });
  else
    ranks->claim([this] { return follow(); }, nullptr);
#endif
}

// The bed cut into the ranks' boxes, once every mesh is in: the decomposition's bounds are the
// domain's box grown by 2 R_max + skin, the same on every N. Every rank does it at the same point
// (its construction, or the last requested mesh's arrival).
void DemAdapter::ranks_split() {
#ifdef PARTITA_DEM_MPI
  OnRanks& o = *ranks_;
  const ParticipantRanks& ranks = *o.ranks;
  const dem::Particles& p = system_.particles();
  double r_max = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    r_max = std::max(r_max, p.radius[i]);
    o.mass += p.mass[i];
  }
  o.particles = static_cast<double>(p.size());
  // (stable_time_step() in one process, over every particle: the set is fixed on ranks)
  o.stable = time_step_fraction_ * system_.rayleigh_time_step();
  if (!(o.skin > 0.0)) o.skin = 0.1 * r_max;  // (the case's, or as one System's default)
  o.wall_force.assign(walls_.size(), Eigen::Vector3d::Zero());
  std::array<Eigen::Vector3d, 6> none;
  none.fill(Eigen::Vector3d::Zero());
  o.face_force.assign(walls_.size(), none);
  o.mesh_force.assign(meshes_dem_.size(), Eigen::Vector3d::Zero());
  o.moved.assign(meshes_dem_.size(), 0);
  o.attached.assign(meshes_dem_.size(), Eigen::MatrixXd());
  try {
    const Eigen::Vector3d pad = Eigen::Vector3d::Constant(2.0 * r_max + o.skin);
    o.decomposition = dem::DomainDecomposition::bisection(p.position, domain_lo_ - pad,
                                                          domain_hi_ + pad, ranks.size());
    std::vector<char> elsewhere(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i)
      elsewhere[i] = o.decomposition.owner(p.position[i]) != ranks.rank();
    system_.remove_particles(elsewhere);
    system_.shrink_to_fit();  // (the rank steps its share: the whole bed's arrays go)
    o.stepper = std::make_unique<dem::SubdomainStepper>(std::vector<dem::System*>{&system_},
                                                        *o.transport, o.decomposition, o.skin);
    o.stepper->set_energy_accounting(o.books);
  } catch (const dem::Error& e) {
    throw Error(std::string("DEM model of participant '") + name_ + "' on ranks: " + e.what());
  }
  if (ranks.leads())
    log::get("adapters")
        ->info("dem '{}': on {} rank(s), {} particles on rank 0, skin {:.3g} m", name_,
               ranks.size(), system_.particle_count(), o.skin);
#endif
}

// ---- commands --------------------------------------------------------------------------------

// Collective work: a failure in it leaves the ranks unable to go on together (the transport's
// PeerTimeout, a dem::Error, says which rank it met).
template <class F>
static auto together(ParticipantRanks& ranks, F&& f) {
  try {
    return f();
  } catch (const dem::Error& e) {
    ranks.set_broken();
    throw Error("the DEM on rank " + std::to_string(ranks.rank()) + ": " + e.what() +
                ranks.world_note());
  } catch (...) {
    ranks.set_broken();
    throw;
  }
}

void DemAdapter::tell_others(const std::vector<std::byte>& bytes) const {
  OnRanks& o = *ranks_;
  if (o.ranks->size() == 1) {
    o.pending.clear();
    return;
  }
  // what read() took since the last command goes ahead of this one, in the same message
  for (std::size_t d = 0; d < o.out[0].size(); ++d) {
    std::vector<std::byte>& to = o.out[0][d];
    to.clear();
    if (d == 0) continue;
    to.insert(to.end(), o.pending.begin(), o.pending.end());
    to.insert(to.end(), bytes.begin(), bytes.end());
  }
  o.pending.clear();
  together(*o.ranks, [&] { o.transport->exchange(o.out, o.in); });
}

std::vector<std::byte> DemAdapter::next_command() const {
  OnRanks& o = *ranks_;
  for (auto& b : o.out[0]) b.clear();
  o.transport->exchange(o.out, o.in);
  if (o.in[0][0].size() < 4)
    throw Error("dem '" + name_ + "' on rank " + std::to_string(o.ranks->rank()) +
                ": rank 0 sent no command");
  return std::move(o.in[0][0]);
}

int DemAdapter::follow() {
  OnRanks& o = *ranks_;
  return together(*o.ranks, [&] {
    for (;;) {
      const std::vector<std::byte> message = next_command();
      Reader in(message);
      while (!in.done()) switch (static_cast<Command>(in.get<std::uint32_t>())) {
          case Command::advance:
            ranks_advance(in.get<double>());
            break;
          case Command::monitors:
            ranks_monitors(in.get<std::uint32_t>());
            break;
          case Command::check:
            ranks_check();
            break;
          case Command::output: {
            OutputFrame f;
            f.vtk_directory = in.string();
            f.prefix = in.string();
            f.index = in.get<int>();
            f.time = in.get<double>();
            f.vtk.format = in.get<vtk::Format>();
            f.vtk.precision = in.get<vtk::Precision>();
            f.vtk.zlib_level = in.get<int>();
            f.vtk.block_size = in.get<std::size_t>();
            ranks_output(f);
            break;
          }
          case Command::restart:
            ranks_restart();
            break;
          case Command::resume:
            ranks_resume(in.string());
            ranks_check();
            break;
          case Command::restore:
            ranks_resume(in.string());
            o.attached.assign(meshes_dem_.size(), Eigen::MatrixXd());
            break;
          case Command::particles_file:
            ranks_particles_file(in.string());
            break;
          case Command::mesh: {
            const std::string name = in.string();
            Mesh::Points points;
            Mesh::Triangles triangles;
            in.matrix(points);
            in.matrix(triangles);
            receive_mesh(name, Mesh(name, std::move(points), std::move(triangles)));
            break;
          }
          case Command::read: {
            const auto k = in.get<std::uint64_t>();
            const auto what = in.get<std::uint32_t>();
            in.matrix(o.values);
            ranks_read(k, what, o.values);
            break;
          }
          case Command::write: {
            const auto k = in.get<std::uint64_t>();
            ranks_write(k, in.get<std::uint32_t>(), o.values);
            break;
          }
          case Command::finish:
            return 0;
          case Command::end:
            return in.get<int>();
          default:
            throw Error("dem '" + name_ + "' on rank " + std::to_string(o.ranks->rank()) +
                        ": an unknown command from rank 0");
        }
    }
  });
}

void DemAdapter::end_others(int status) {
  OnRanks& o = *ranks_;
  if (!o.ranks->leads() || o.ended || o.ranks->broken()) return;
  o.ended = true;
  if (o.ranks->size() > 1)
    log::get("adapters")
        ->info("dem '{}' on {} ranks: the bed was cut again {} time(s) as the load drifted", name_,
               o.ranks->size(), o.rebalances);
  Bytes b(status == 0 ? Command::finish : Command::end);
  b.put(status);
  tell_others(b.bytes());
}

// ---- coupled data ----------------------------------------------------------------------------

// A mesh handed over by another participant (the leader got it at the run's set-up): passed on
// to the others, who add it alike (with the one_sided flag of their own, the same, case).
void DemAdapter::lead_mesh(const std::string& name, const Mesh& mesh) const {
  Bytes b(Command::mesh);
  b.put(name).put_matrix(mesh.points()).put_matrix(mesh.triangles());
  tell_others(b.bytes());
}

void DemAdapter::lead_read(std::size_t k, std::uint32_t what, const Eigen::MatrixXd& values) {
  OnRanks& o = *ranks_;
  if (what == OnRanks::kAttached && o.attached[k].rows() == values.rows() &&
      o.attached[k].cols() == values.cols() && o.attached[k] == values)
    return;  // (the same as the last: the triangles' states do not change)
  if (what == OnRanks::kAttached) o.attached[k] = values;
  // ahead of the next command (no message of its own)
  Bytes b(Command::read);
  b.put(static_cast<std::uint64_t>(k)).put(what).put_matrix(values);
  o.pending.insert(o.pending.end(), b.bytes().begin(), b.bytes().end());
  ranks_read(k, what, values);
}

// Every rank's System holds every mesh whole: each moves it (or sets its triangles' states)
// alike, as one process does.
void DemAdapter::ranks_read(std::size_t k, std::uint32_t what, const Eigen::MatrixXd& values) {
  CouplingMesh& cm = meshes_dem_.at(k);
  if (what == OnRanks::kAttached) {
    set_attached(cm, values);
    return;
  }
  if (values.rows() != cm.reference.rows() || values.cols() != 3)
    throw Error(
        fmt::format("dem '{}': the displacement of mesh '{}' has {} x {} values, not {} x 3", name_,
                    cm.name, values.rows(), values.cols(), cm.reference.rows()));
  cm.positions = cm.reference + values;
  system_.set_vertex_positions(cm.id, cm.positions);
  ranks_->moved[k] = 1;
}

void DemAdapter::lead_write(std::size_t k, std::uint32_t what, Eigen::MatrixXd& values) const {
  Bytes b(Command::write);
  b.put(static_cast<std::uint64_t>(k)).put(what);
  tell_others(b.bytes());
  ranks_write(k, what, values);
}

// The forces on a mesh summed over the ranks (SubdomainStepper: each vertex's an exact sum over
// the owned particles' contacts, rounded once; the same bits on any N); collective. Before the
// first step after a resume there is no pass whose forces they would be: zero (as the output's).
void DemAdapter::ranks_write(std::size_t k, std::uint32_t what, Eigen::MatrixXd& values) const {
  OnRanks& o = *ranks_;
  ranks_start();
  const CouplingMesh& cm = meshes_dem_.at(k);
  const dem::TriangleMesh& tm = system_.mesh(cm.id);
  together(*o.ranks, [&] {
    if (what == OnRanks::kVertexForce) {
      if (o.forces)
        values = o.stepper->vertex_forces(cm.id);
      else
        values.setZero(static_cast<Eigen::Index>(tm.positions().size()), 3);
      return;
    }
    if (o.forces)
      values = o.stepper->triangle_forces(cm.id);
    else
      values.setZero(static_cast<Eigen::Index>(tm.triangle_count()), 3);
    // t_i = f_i / A_i, as in one process
    if (what == OnRanks::kTraction) values.array() = values.array().colwise() / cm.areas.array();
  });
}

// ---- advance ---------------------------------------------------------------------------------

// The first command starts the stepper on every rank: migration to the owners, ghosts, lists and
// a force pass without a kick at the stable step (which no step of the run exceeds; a pass without
// a kick updates no history), so that the quantities at t = 0 have forces, as every later one.
void DemAdapter::ranks_start() const {
  OnRanks& o = *ranks_;
  if (o.started) return;
  together(*o.ranks, [&] { o.stepper->start(o.stable); });
  o.started = true;
  o.forces = true;
}

void DemAdapter::lead_advance(double dt) {
  Bytes b(Command::advance);
  b.put(dt);
  tell_others(b.bytes());
  ranks_advance(dt);
}

void DemAdapter::ranks_advance(double dt) {
  OnRanks& o = *ranks_;
  // walls with a velocity table move with the factor at the middle of the step, alike on every
  // rank (as advance() in one process)
  for (const auto& w : walls_)
    if (w.moving) system_.set_wall_velocity(w.id, w.velocity * w.table(system_.time() + 0.5 * dt));
  ranks_start();
  // a step that fragments made too long for the stable step (the smallest over the ranks) is
  // split into as many equal steps as the new one needs, alike on every rank (as in one process)
  int parts = 1;
  if (breakage_ >= 0 && coupling::TimeWindow::longer_than(dt, o.stable))
    parts = coupling::TimeWindow::substeps_for(dt, o.stable);
  together(*o.ranks, [&] {
    try {
      for (int k = 0; k < parts; ++k) {
        o.stepper->step(dt / parts);
        if (o.stepper->replacement_steps() != o.replacements) ranks_set_changed();
      }
    } catch (const dem::Error& e) {
      throw Error(fmt::format("dem '{}' on rank {} at t = {:.6g} s: {}{}", name_, o.ranks->rank(),
                              system_.time(), e.what(), o.ranks->world_note()));
    }
  });
  o.forces = true;
  // servo walls: dem::WallServo::end_of_step()'s law, v = clamp(gain (F_target - F_n), -v_max,
  // v_max) along the normal, F_n = -F_wall . n with the wall's force summed over the ranks (an
  // exact sum: the same velocity on every rank and every N)
  for (const auto& w : walls_) {
    if (!w.servo) continue;
    const dem::WallServoParameters& sp = *w.servo;
    const Eigen::Vector3d f = together(*o.ranks, [&] { return o.stepper->wall_force(w.id); });
    const double v =
        std::clamp(sp.gain * (sp.force + f.dot(sp.normal)), -sp.max_velocity, sp.max_velocity);
    system_.set_wall_velocity(w.id, v * sp.normal);
  }
  // the work the moving meshes did on the particles over this step, from their vertex forces
  // summed over the ranks (collective: every rank asks; the leader keeps the audit). A mesh that
  // no displacement has moved does no work (and costs no sum).
  for (std::size_t k = 0; k < meshes_dem_.size(); ++k) {
    if (!o.moved[k]) continue;
    CouplingMesh& cm = meshes_dem_[k];
    const Eigen::MatrixX3d* f = nullptr;
    together(*o.ranks, [&] { f = &o.stepper->vertex_forces(cm.id); });
    if (o.ranks->leads()) cm.audit.motion_step(cm.positions, *f);
  }
  if (o.stepper->steps() % kBalanceEvery == 0) ranks_rebalance();
}

// After a change of the particle set (breakage) or a resume: the particle count and mass over
// the ranks (exact sums), the stable step (the smallest over the ranks); collective.
void DemAdapter::ranks_set_changed() const {
  OnRanks& o = *ranks_;
  const auto [count, mass] = o.stepper->particle_totals();
  o.particles = static_cast<double>(count);
  o.mass = mass;
  o.stable = time_step_fraction_ * o.stepper->rayleigh_time_step();
  o.replacements = o.stepper->replacement_steps();
}

// The load drifts as the bed moves (a bed settling empties the upper boxes, a bed flowing down a
// chute fills the lower ones): every kBalanceEvery steps the ranks compare their owned counts,
// and when the largest exceeds the mean by more than kImbalance the bed is cut again by the same
// bisection, from the positions of now (every rank gathers every owned position: 24 bytes a
// particle to each rank, rare), with the same bounds. The stepper takes the new boxes at its next
// list build; the results do not change (the sums run in the global order, whatever the boxes),
// only where each particle is stepped. Why not a finer rule (cost per particle, contacts): the
// counts are what each rank knows at once, and the pass per particle is most of a step.
void DemAdapter::ranks_rebalance() {
  OnRanks& o = *ranks_;
  together(*o.ranks, [&] {
    const dem::Subdomain& sd = o.stepper->subdomain(0);
    const double owned = static_cast<double>(sd.owned_count());
    const double most = o.transport->max({owned});
    const double mean = o.particles / o.ranks->size();
    if (!(most > kImbalance * mean)) return;
    const dem::Particles& p = system_.particles();
    Bytes mine;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (!sd.is_ghost(i))
        mine.put(p.position[i].x()).put(p.position[i].y()).put(p.position[i].z());
    const auto me = static_cast<std::size_t>(o.ranks->rank());
    for (std::size_t d = 0; d < o.out[0].size(); ++d)
      if (d == me)
        o.out[0][d].clear();
      else
        o.out[0][d] = mine.bytes();
    o.transport->exchange(o.out, o.in);
    std::vector<Eigen::Vector3d> all;
    all.reserve(static_cast<std::size_t>(o.particles));
    const auto take = [&](const std::vector<std::byte>& from) {
      Reader in(from);
      while (!in.done()) {
        const double x = in.get<double>(), y = in.get<double>();
        all.emplace_back(x, y, in.get<double>());
      }
    };
    take(mine.bytes());
    for (std::size_t r = 0; r < o.in[0].size(); ++r)
      if (r != me) take(o.in[0][r]);
    const dem::DomainDecomposition::Box& b = o.decomposition.bounds();
    o.decomposition = dem::DomainDecomposition::bisection(all, b.lo, b.hi, o.ranks->size());
    o.stepper->set_decomposition(o.decomposition);
    ++o.rebalances;
    if (o.ranks->leads())
      log::get("adapters")
          ->debug(
              "dem '{}' at t = {:.6g} s: the bed cut again ({} particles on the fullest rank, "
              "{:.4g} on average)",
              name_, system_.time(), most, mean);
  });
}

// ---- monitors --------------------------------------------------------------------------------

std::vector<std::string> DemAdapter::ranks_monitor_names() const {
  std::vector<std::string> n = {
      "kinetic_energy", "particles",  "mass",           "momentum_x",
      "momentum_y",     "momentum_z", "elastic_energy", "contacts_per_particle"};
  for (const auto& m : meshes_dem_)
    for (const char* c : {"x", "y", "z"}) n.push_back(m.name + ".force_" + c);
  for (const auto& w : walls_)
    for (const char* c : {"x", "y", "z"}) n.push_back(w.name + ".force_" + c);
  if (breakage_ >= 0) n.insert(n.end(), std::begin(kBreakageNames), std::end(kBreakageNames));
  if (ranks_->books) {
    n.insert(n.end(), std::begin(kEnergyNames), std::end(kEnergyNames));
    for (const auto& m : meshes_dem_) n.push_back(m.name + ".work");
    for (const auto& w : walls_) n.push_back(w.name + ".work");
  }
  for (const auto& w : walls_)
    for (int face = 0; face < 6; ++face)
      if (w.faces & (1u << face))
        for (const char* c : {"x", "y", "z"})
          n.push_back(w.name + "." + std::string(kFaces[static_cast<std::size_t>(face)]) +
                      ".force_" + c);
  for (const std::int64_t id : tracked_)
    for (const char* c : kComponents) n.push_back(fmt::format("particle.{}.{}", id, c));
  return n;
}

std::uint32_t DemAdapter::ranks_monitor_groups(const std::vector<std::string>& names) const {
  std::uint32_t groups = 0;
  for (const std::string& q : names) {
    const auto is = [&](const std::string& prefix, std::initializer_list<const char*> rows) {
      for (const char* r : rows)
        if (q == prefix + r) return true;
      return false;
    };
    bool known = false;
    if (q == "kinetic_energy" || is("momentum_", {"x", "y", "z"})) groups |= kKinetic, known = true;
    if (q == "particles" || q == "mass") known = true;
    if (q == "elastic_energy") groups |= kElastic, known = true;
    if (q == "contacts_per_particle") groups |= kContacts, known = true;
    if (breakage_ >= 0)
      for (const char* e : kBreakageNames)
        if (q == e) groups |= kBreakage, known = true;
    if (ranks_->books) {
      for (const char* e : kEnergyNames)
        if (q == e) groups |= kEnergy, known = true;
      for (const auto& m : meshes_dem_)
        if (q == m.name + ".work") groups |= kEnergy, known = true;
      for (const auto& w : walls_)
        if (q == w.name + ".work") groups |= kEnergy, known = true;
    }
    for (const auto& m : meshes_dem_)
      if (is(m.name + ".force_", {"x", "y", "z"})) groups |= kMeshes, known = true;
    for (const auto& w : walls_) {
      if (is(w.name + ".force_", {"x", "y", "z"})) groups |= kWalls, known = true;
      for (int face = 0; face < 6; ++face)
        if ((w.faces & (1u << face)) &&
            is(w.name + "." + std::string(kFaces[static_cast<std::size_t>(face)]) + ".force_",
               {"x", "y", "z"}))
          groups |= kFaceGroup, known = true;
    }
    for (const std::int64_t id : tracked_)
      if (is(fmt::format("particle.{}.", id), {"x", "y", "z", "vx", "vy", "vz"}))
        groups |= kTracked, known = true;
    if (!known)
      throw Error(fmt::format(
          "dem '{}': the monitor quantity '{}.{}' (monitors: quantities) is not yet on several "
          "ranks (mpirun -n {} partita run splits the bed over the ranks); on several ranks a "
          "DEM reports {}; or run this case in one process, without mpirun",
          name_, name_, q, ranks_->ranks->size(), join_names(ranks_monitor_names())));
  }
  return groups;
}

std::vector<MonitorValue> DemAdapter::lead_monitors(const std::vector<std::string>& names) const {
  const std::vector<std::string> all = names.empty() ? ranks_monitor_names() : names;
  const std::uint32_t groups = ranks_monitor_groups(all);  // (refused before telling the others)
  if (groups != 0) {
    Bytes b(Command::monitors);
    b.put(groups);
    tell_others(b.bytes());
    ranks_monitors(groups);
  }
  return monitor_table().values(*this, all);
}

void DemAdapter::ranks_monitors(std::uint32_t groups) const {
  OnRanks& o = *ranks_;
  ranks_start();
  dem::SubdomainStepper& s = *o.stepper;
  together(*o.ranks, [&] {
    if (groups & kKinetic) {
      o.kinetic = s.kinetic_energy();
      o.momentum = s.linear_momentum();
    }
    // the forces of a pass: none after a resume before its first step
    if (groups & kElastic) o.elastic = o.forces ? s.elastic_energy() : 0.0;
    if (groups & kEnergy) {  // the books go on through a resume; their balance needs the forces
      o.energies = s.energies();
      o.balance = o.forces ? s.energy_balance_error() : 0.0;
    }
    if (groups & kBreakage)
      o.breakage = dem::Breakage::counters_from(s.hook_sums(breakage_));
    // 2 contacts / N, as System::mean_contacts_per_particle()
    if (groups & kContacts)
      o.contacts_per_particle = 2.0 * static_cast<double>(s.contact_count()) / o.particles;
    if (groups & kWalls) {
      const std::vector<Eigen::Vector3d>* f = o.forces ? &s.wall_forces() : nullptr;
      for (std::size_t k = 0; k < walls_.size(); ++k)
        o.wall_force[k] =
            f ? (*f)[static_cast<std::size_t>(walls_[k].id)] : Eigen::Vector3d::Zero();
    }
    if (groups & kFaceGroup) {
      // a box wall's face k is its plane of normal +e_axis (k even) or -e_axis (k odd), as
      // dem::WallContacts::face_force() finds it
      const std::vector<Eigen::Vector3d>* f = o.forces ? &s.plane_forces() : nullptr;
      const std::vector<dem::PlaneWall>& planes = system_.planes();
      for (std::size_t k = 0; k < walls_.size(); ++k)
        for (int face = 0; face < 6; ++face) {
          Eigen::Vector3d& v = o.face_force[k][static_cast<std::size_t>(face)];
          v.setZero();
          for (std::size_t q = 0; f && q < planes.size(); ++q)
            if (planes[q].wall == walls_[k].id &&
                planes[q].normal[face / 2] == (face % 2 == 0 ? 1.0 : -1.0)) {
              v = (*f)[q];
              break;
            }
        }
    }
    if (groups & kMeshes)
      for (std::size_t k = 0; k < meshes_dem_.size(); ++k)
        o.mesh_force[k] = o.forces ? s.mesh_force(meshes_dem_[k].id) : Eigen::Vector3d::Zero();
    if (groups & kTracked) {
      // each monitored particle's state from the rank that owns it
      const dem::Subdomain& sd = s.subdomain(0);
      const dem::Particles& p = system_.particles();
      Bytes mine;
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (sd.is_ghost(i)) continue;
        const auto k = std::find(tracked_.begin(), tracked_.end(), p.id[i]) - tracked_.begin();
        if (k == static_cast<std::ptrdiff_t>(tracked_.size())) continue;
        mine.put(static_cast<std::uint64_t>(k));
        for (int c = 0; c < 3; ++c) mine.put(p.position[i][c]);
        for (int c = 0; c < 3; ++c) mine.put(p.velocity[i][c]);
      }
      const auto take = [&](const std::vector<std::byte>& from) {
        Reader in(from);
        while (!in.done()) {
          auto& last = tracked_last_.at(in.get<std::uint64_t>());
          for (double& v : last) v = in.get<double>();
        }
      };
      for (auto& b : o.out[0]) b.clear();
      if (!o.ranks->leads()) {
        o.out[0][0] = mine.bytes();
        o.transport->exchange(o.out, o.in);
      } else {
        take(mine.bytes());
        if (o.ranks->size() > 1) {
          o.transport->exchange(o.out, o.in);
          for (std::size_t r = 1; r < o.in[0].size(); ++r) take(o.in[0][r]);
        }
      }
    }
  });
}

// ---- the state check -------------------------------------------------------------------------

std::string DemAdapter::lead_check() const {
  tell_others(Bytes(Command::check).bytes());
  return ranks_check();
}

std::string DemAdapter::ranks_check() const {
  OnRanks& o = *ranks_;
  ranks_start();
  // this rank's owned particle of lowest id that is not finite or lies beyond the domain and
  // lost_margin (as System::first_particle_astray() in one process)
  const dem::Subdomain& sd = o.stepper->subdomain(0);
  const dem::Particles& p = system_.particles();
  std::int64_t id = std::numeric_limits<std::int64_t>::max();
  std::string message;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (sd.is_ghost(i) || p.id[i] >= id) continue;
    const Eigen::Vector3d& x = p.position[i];
    if (!x.allFinite() || !p.velocity[i].allFinite() ||
        std::max((domain_lo_ - x).maxCoeff(), (x - domain_hi_).maxCoeff()) > lost_margin_) {
      id = p.id[i];
      message = astray_message(i, false);
    }
  }
  // (with it, a stop signal that reached this rank's process alone: rank 0 stops the run after
  // the window, as for a signal to its own; ParticipantRanks)
  return together(*o.ranks, [&]() -> std::string {
    for (auto& b : o.out[0]) b.clear();
    if (!o.ranks->leads()) {
      const int signal = o.ranks->stop_signal();
      if (!message.empty() || signal != 0)
        o.out[0][0] = Bytes().put(static_cast<std::int32_t>(signal)).put(id).put(message).bytes();
      o.transport->exchange(o.out, o.in);
      return {};
    }
    if (o.ranks->size() > 1) {
      o.transport->exchange(o.out, o.in);
      for (std::size_t r = 1; r < o.in[0].size(); ++r) {
        if (o.in[0][r].empty()) continue;
        Reader in(o.in[0][r]);
        o.ranks->raise_stop(in.get<std::int32_t>());
        const auto other = in.get<std::int64_t>();
        std::string text = in.string();
        if (!text.empty() && other < id) id = other, message = std::move(text);
      }
    }
    return message;
  });
}

// ---- output ----------------------------------------------------------------------------------

void DemAdapter::lead_output(const OutputFrame& frame) {
  // a new run's first frame: the pieces of an earlier run into this folder go (an earlier run on
  // more ranks would leave pieces no .pvtp lists), before any rank writes its own
  if (frame.index == 0) remove_particle_pieces(frame.vtk_directory, frame.prefix);
  Bytes b(Command::output);
  b.put(frame.vtk_directory.string()).put(frame.prefix).put(frame.index).put(frame.time);
  b.put(frame.vtk.format).put(frame.vtk.precision).put(frame.vtk.zlib_level);
  b.put(frame.vtk.block_size);
  tell_others(b.bytes());
  ranks_output(frame);
}

void DemAdapter::ranks_output(const OutputFrame& frame) {
  OnRanks& o = *ranks_;
  ranks_start();
  const int rank = o.ranks->rank();
  const std::string stem = fmt::format("{}_particles_{:06d}", frame.prefix, frame.index);
  // this rank's owned particles, one piece
  {
    const dem::Subdomain& sd = o.stepper->subdomain(0);
    const dem::Particles& p = system_.particles();
    dem::Particles owned;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (sd.is_ghost(i)) continue;
      owned.position.push_back(p.position[i]);
      owned.velocity.push_back(p.velocity[i]);
      owned.angular_velocity.push_back(p.angular_velocity[i]);
      owned.force.push_back(p.force[i]);
      owned.radius.push_back(p.radius[i]);
      owned.id.push_back(p.id[i]);
    }
    write_particles_vtp(owned, frame.vtk_directory / fmt::format("{}_{}.vtp", stem, rank),
                        frame.vtk);
  }
  // the meshes with the forces summed over the ranks (collective), written by rank 0
  std::vector<std::pair<Eigen::MatrixX3d, Eigen::MatrixX3d>> forces;  // vertices, triangles
  together(*o.ranks, [&] {
    for (const auto& m : meshes_dem_) {
      const dem::TriangleMesh& tm = system_.mesh(m.id);
      Eigen::MatrixX3d v =
          Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(tm.positions().size()), 3);
      Eigen::MatrixX3d t =
          Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(tm.triangle_count()), 3);
      if (o.forces) {
        t = o.stepper->triangle_forces(m.id);
        v = o.stepper->vertex_forces(m.id);
      }
      forces.emplace_back(std::move(v), std::move(t));
    }
  });
  if (particles_file_ == "every-output") {
    const std::filesystem::path dir = frame.vtk_directory.parent_path() / "particles";
    if (o.ranks->leads()) std::filesystem::create_directories(dir);
    ranks_particles_file(dir / fmt::format("{}_{:06d}.data", frame.prefix, frame.index));
  }
  // the grading from every rank's particles, in the order of their ids (the same on any N)
  if (breakage_ >= 0) {
    const dem::Particles all = ranks_particles();  // (collective)
    if (o.ranks->leads()) write_grading(frame, all);
  }
  if (!o.ranks->leads()) return;
  files_.clear();
  std::vector<std::string> pieces;
  for (int r = 0; r < o.ranks->size(); ++r) pieces.push_back(fmt::format("{}_{}.vtp", stem, r));
  write_particles_pvtp(frame.vtk_directory / (stem + ".pvtp"), pieces, frame.vtk);
  files_.emplace_back("particles", stem + ".pvtp");
  for (std::size_t k = 0; k < meshes_dem_.size(); ++k) {
    const auto& m = meshes_dem_[k];
    const std::string mfile = fmt::format("{}_{}_{:06d}.vtp", frame.prefix, m.name, frame.index);
    write_mesh_vtp(system_, m.id, frame.vtk_directory / mfile, frame.vtk, forces[k].first,
                   forces[k].second);
    files_.emplace_back(m.name, mfile);
  }
}

// ---- the particles file ----------------------------------------------------------------------

dem::Particles DemAdapter::ranks_particles() const {
  OnRanks& o = *ranks_;
  ranks_start();
  const dem::Subdomain& sd = o.stepper->subdomain(0);
  const dem::Particles& p = system_.particles();
  Bytes mine;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (sd.is_ghost(i)) continue;
    mine.put(p.id[i]).put(p.material[i]).put(p.radius[i]).put(p.mass[i]);
    for (const Eigen::Vector3d* v : {&p.position[i], &p.velocity[i], &p.angular_velocity[i]})
      mine.put(v->x()).put(v->y()).put(v->z());
  }
  return together(*o.ranks, [&] {
    dem::Particles all;
    for (auto& b : o.out[0]) b.clear();
    if (!o.ranks->leads()) {
      o.out[0][0] = mine.bytes();
      o.transport->exchange(o.out, o.in);
      return all;
    }
    if (o.ranks->size() > 1) o.transport->exchange(o.out, o.in);
    struct Row {
      std::int64_t id;
      int material;
      double radius, mass;
      Eigen::Vector3d x, v, w;
    };
    std::vector<Row> rows;
    rows.reserve(static_cast<std::size_t>(o.particles));
    const auto take = [&](const std::vector<std::byte>& from) {
      Reader in(from);
      while (!in.done()) {
        Row r;
        r.id = in.get<std::int64_t>();
        r.material = in.get<int>();
        r.radius = in.get<double>();
        r.mass = in.get<double>();
        for (Eigen::Vector3d* v : {&r.x, &r.v, &r.w})
          for (int c = 0; c < 3; ++c) (*v)[c] = in.get<double>();
        rows.push_back(r);
      }
    };
    take(mine.bytes());
    for (std::size_t r = 1; r < o.in[0].size() && o.ranks->size() > 1; ++r) take(o.in[0][r]);
    std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.id < b.id; });
    all.reserve(rows.size());
    for (const Row& r : rows) {
      all.id.push_back(r.id);
      all.material.push_back(r.material);
      all.radius.push_back(r.radius);
      all.mass.push_back(r.mass);
      all.inertia.push_back(0.4 * r.mass * r.radius * r.radius);
      all.position.push_back(r.x);
      all.velocity.push_back(r.v);
      all.angular_velocity.push_back(r.w);
      all.force.push_back(Eigen::Vector3d::Zero());
      all.torque.push_back(Eigen::Vector3d::Zero());
    }
    return all;
  });
}

void DemAdapter::lead_particles_file(const std::filesystem::path& file) {
  Bytes b(Command::particles_file);
  b.put(file.string());
  tell_others(b.bytes());
  ranks_particles_file(file);
}

void DemAdapter::ranks_particles_file(const std::filesystem::path& file) const {
  const dem::Particles all = ranks_particles();
  if (ranks_->ranks->leads()) write_particles_file(all, file);
}

// ---- restart ---------------------------------------------------------------------------------

std::string DemAdapter::lead_restart() const {
  tell_others(Bytes(Command::restart).bytes());
  return ranks_restart();
}

std::string DemAdapter::ranks_restart() const {
  OnRanks& o = *ranks_;
  ranks_start();
  return together(*o.ranks, [&]() -> std::string {
    const dem::SplitRestart r = dem::SplitRestart::gather(*o.stepper);
    if (!r.holds()) return {};
    std::ostringstream out(std::ios::binary);
    r.write(out);
    return std::move(out).str();
  });
}

std::string DemAdapter::lead_resume(const std::string& stream, const std::string& source) {
  // read here first: a stream that is not a split bed's is refused before the others resume it
  try {
    std::istringstream in(stream, std::ios::binary);
    (void)dem::SplitRestart::read(in);
  } catch (const dem::Error& e) {
    throw Error(source + ": the DEM state of '" + name_ + "' on ranks: " + e.what());
  }
  Bytes b(Command::resume);
  b.put(stream);
  tell_others(b.bytes());
  ranks_resume(stream);
  return ranks_check();
}

// A checkpoint (an implicit scheme) is the split bed as a restart stream (save_checkpoint():
// lead_restart(), gathered to the leader); restoring it resumes it on every rank, as a restart
// file does: the same bits on any N (SplitRestart). The triangles' states come back with the
// world, so the next `attached` values are passed on whatever the last ones were.
void DemAdapter::lead_restore(const std::string& stream) {
  Bytes b(Command::restore);
  b.put(stream);
  tell_others(b.bytes());
  ranks_resume(stream);
  ranks_->attached.assign(meshes_dem_.size(), Eigen::MatrixXd());
}

void DemAdapter::ranks_resume(const std::string& stream) {
  OnRanks& o = *ranks_;
  together(*o.ranks, [&] {
    try {
      std::istringstream in(stream, std::ios::binary);
      const dem::SplitRestart r = dem::SplitRestart::read(in);
      // Systems alike without particles, then the restart's world and (on rank 0) every particle;
      // a new stepper over them, whose first build sends each particle to its owner
      o.stepper.reset();
      system_.remove_particles(std::vector<char>(system_.particle_count(), 1));
      r.restore({&system_}, *o.transport);
      o.stepper = std::make_unique<dem::SubdomainStepper>(std::vector<dem::System*>{&system_},
                                                          *o.transport, o.decomposition, o.skin);
      o.stepper->set_energy_accounting(o.books);
      o.stepper->resume();
      if (o.books) o.stepper->restore_books(r.books());
      o.started = true;
      o.forces = false;
      ranks_set_changed();
    } catch (const dem::Error& e) {
      throw Error(fmt::format("dem '{}' on rank {}: resuming the restart: {}", name_,
                              o.ranks->rank(), e.what()));
    }
  });
}

}  // namespace partita::adapters
