// CaseRun: restart files, the run-time checks after each window and the balance audit.

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "partita/coupling/elementwise.hpp"
#include "partita/run/case_run.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace fs = std::filesystem;

namespace {

constexpr const char* kMagic = "partita restart file";
constexpr std::uint32_t kVersion = 5;  // 2: the energy audit; 3: section checksums; 4: the
                                       // energy balance; 5: when its largest error occurred
constexpr std::uint32_t kByteOrder = 0x01020304u;

// DIR/restart/w000000001234.bin -> 1234; -1 for other names.
std::int64_t window_of(const fs::path& p) {
  const std::string n = p.filename().string();
  if (n.size() != 17 || n[0] != 'w' || p.extension() != ".bin") return -1;
  std::int64_t w = 0;
  for (std::size_t i = 1; i < 13; ++i) {
    if (n[i] < '0' || n[i] > '9') return -1;
    w = 10 * w + (n[i] - '0');
  }
  return w;
}

std::vector<std::pair<std::int64_t, fs::path>> restart_files(const fs::path& dir) {
  std::vector<std::pair<std::int64_t, fs::path>> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (const std::int64_t w = window_of(e.path()); w >= 0 && e.is_regular_file())
      files.emplace_back(w, e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Every value finite: x - x is 0 for a finite x and NaN for an infinity or a NaN, and a NaN
// stays in a sum. Eight independent sums (no chain of dependent additions, no overflow of a
// plain sum of the values) in one pass over the array; about 3 times faster than sum().
bool all_finite(const Eigen::MatrixXd& v) {
  const double* x = v.data();
  const Eigen::Index n = v.size();
  double acc[8] = {};
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8)
    for (int j = 0; j < 8; ++j) acc[j] += x[i + j] - x[i + j];
  for (; i < n; ++i) acc[0] += x[i] - x[i];
  double all = 0.0;
  for (const double a : acc) all += a;
  return all == 0.0;
}

// The totals of each component of v (sums for extensive data, integrals over the point weights
// for intensive data) into `total`; where `magnitudes`, the same of the vector lengths |v_q|
// (the scale the imbalance is measured against) into `magnitude`; where u is given (a vector
// of the points' bound weights), sum_q u_q |v_q| into `bound`. One pass over the values.
// Vectors take the fused kernel; other component counts plain Eigen passes (the caller keeps
// `total` and `norm`: no allocation per window).
void totals(const Eigen::MatrixXd& v, const Mesh& mesh, bool extensive, bool magnitudes,
            const Eigen::VectorXd* u, Eigen::VectorXd& total, Eigen::ArrayXd& norm,
            double& magnitude, double& bound) {
  total.resize(v.cols());
  const double* w = extensive ? nullptr : mesh.weights().data();
  if (v.cols() == 3) {
    const elementwise::Totals3 t =
        elementwise::weighted_totals3(v.col(0).data(), v.col(1).data(), v.col(2).data(), w,
                                      v.rows(), magnitudes, u ? u->data() : nullptr);
    total = Eigen::Map<const Eigen::Vector3d>(t.total);
    magnitude = t.magnitude;
    bound = t.bound;
    return;
  }
  if (extensive)
    total.noalias() = v.colwise().sum().transpose();
  else
    total.noalias() = v.transpose() * mesh.weights();
  if (!magnitudes && !u) return;
  norm = v.rowwise().norm().array();
  magnitude = extensive ? norm.sum() : (norm * mesh.weights().array().abs()).sum();
  bound = u ? (norm * u->array()).sum() : 0.0;
}

}  // namespace

std::string CaseRun::restart_blocker() const {
  std::string why;  // every participant that cannot, each with its fix
  for (const auto& p : participants_) {
    if (p->supports_restart()) continue;
    if (!why.empty()) why += "; ";
    if (const auto e = external_programs_.find(p->name()); e != external_programs_.end())
      why += fmt::format(
          "the external program {} did not call set_restart_writer() before initialize(), so it "
          "has no part to write in a restart file or to read back: in the program, call "
          "ExternalParticipant::set_restart_writer(f) before initialize() (f gives the program's "
          "state as bytes; a resumed run gives them back through restart_state()), or run "
          "without restart files",
          e->second);
    else
      why += "participant '" + p->name() + "' has a solver that cannot write restart files";
  }
  return why;
}

fs::path CaseRun::newest_restart_file() const {
  const fs::path dir = output_dir_ / "restart";
  if (!fs::is_directory(output_dir_))
    throw Error("--resume " + output_dir_.string() +
                ": no such folder (give a run's output folder)");
  const auto files = restart_files(dir);
  if (files.empty())
    throw Error("--resume " + output_dir_.string() + ": no restart file in " + dir.string() +
                " (a run writes them with output.restart: {every_windows: N}, at its end, or "
                "when stopped by SIGINT/SIGTERM)");
  return files.back().second;
}

// The file's layout after the magic, version and byte order; the same function writes and reads
// (StateArchive). Counts are written for the lists whose length the
// file decides (monitors are checked against the case by the caller; the energy pairs' count
// comes from the case).
void CaseRun::SavedRun::serialize_case(StateArchive& ar) {
  ar.io(name);
  ar.io(identity);
  ar.io(window_size);
}

void CaseRun::SavedRun::serialize_state(StateArchive& ar) {
  ar.io(progress.windows_done);
  ar.io(progress.frame);
  ar.io(progress.next_output);
  ar.io(iterations);
  ar.io(unconverged_windows);
  ar.io(max_window_iterations);
  ar.io(imbalance_warnings);
  ar.section("energy audit");
  ar.io(energy_warnings);
  for (Pair& p : pairs) {
    ar.io(p.last_a);
    ar.io(p.last_b);
    ar.io(p.passed);
    ar.io(p.over);
  }
  ar.section("energy balance");
  ar.io(energy_started);
  ar.io(energy_initial);
  ar.io(energy_balance_warnings);
  ar.io(max_energy_balance_error);
  ar.io(max_energy_balance_time);
  ar.io(max_energy_balance_window);
  ar.io(energy_balance_uncounted);
  ar.io(energy_csv);
  ar.section("csv");
  ar.io(coupling_csv);
  auto count = static_cast<std::uint64_t>(monitors.size());
  ar.io(count);
  if (ar.reading()) {
    if (count > monitors.size()) ar.fail(fmt::format("{} monitors (found {})", monitors.size(), count));
    monitors.resize(count);
  }
  for (auto& [monitor, text] : monitors) {
    ar.io(monitor);
    ar.io(text);
  }
  ar.section("vtk");
  count = static_cast<std::uint64_t>(pvds.size());
  ar.io(count);
  if (ar.reading()) pvds.clear();
  for (std::uint64_t i = 0; i < count; ++i) {
    if (ar.reading()) pvds.emplace_back();
    auto& [series, entries] = pvds[i];
    ar.io(series);
    auto n = static_cast<std::uint64_t>(entries.size());
    ar.io(n);
    if (ar.reading()) {
      entries.clear();
      for (std::uint64_t k = 0; k < n; ++k) {
        double t = 0.0;
        std::string f;
        ar.io(t);
        ar.io(f);
        entries.emplace_back(t, std::move(f));
      }
    } else {
      for (auto& [t, f] : entries) {
        ar.io(t);
        ar.io(f);
      }
    }
  }
}

CaseRun::SavedRun CaseRun::saved_run(const Progress& progress) const {
  SavedRun r;
  r.name = name_;
  r.identity = identity_;
  r.window_size = window_size_;
  r.progress = progress;
  r.iterations = summary_.iterations;
  r.unconverged_windows = summary_.unconverged_windows;
  r.max_window_iterations = summary_.max_window_iterations;
  r.imbalance_warnings = summary_.imbalance_warnings;
  r.energy_warnings = summary_.energy_warnings;
  for (const auto& p : energy_pairs_) r.pairs.push_back({p.last_a, p.last_b, p.passed, p.over});
  r.coupling_csv = coupling_csv_.text();
  for (const auto& m : monitors_) r.monitors.emplace_back(m.name, m.csv.text());
  if (energy_) {
    r.energy_started = energy_->started() ? 1 : 0;
    r.energy_initial = energy_->initial();
    r.energy_csv = energy_csv_.text();
  }
  r.energy_balance_warnings = summary_.energy_balance_warnings;
  r.max_energy_balance_error = summary_.max_energy_balance_error;
  r.max_energy_balance_time = summary_.max_energy_balance_time;
  r.max_energy_balance_window = summary_.max_energy_balance_window;
  r.energy_balance_uncounted = summary_.energy_balance_uncounted;
  for (const auto& [series, pvd] : pvds_) r.pvds.emplace_back(series, pvd.entries());
  return r;
}

void CaseRun::write_restart_file(const Progress& progress) {
  Stopwatch clock;
  const fs::path dir = output_dir_ / "restart";
  fs::create_directories(dir);
  const fs::path path = dir / fmt::format("w{:012d}.bin", progress.windows_done);
  {
    AtomicFile file(path, /*binary=*/true);
    BinaryWriter out(file.stream());
    out.write(std::string(kMagic));
    out.write(kVersion);
    out.write(kByteOrder);
    SavedRun run = saved_run(progress);
    StateArchive ar(out);
    run.serialize_case(ar);
    run.serialize_state(ar);
    scheme_->serialize(ar);
    out.write(static_cast<std::uint64_t>(participants_.size()));
    for (const auto& p : participants_) {
      out.section("participant " + p->name());
      p->write_restart(out);
    }
    out.section("end");
    out.finish();  // the sections' CRC-32 table
    file.commit();
  }
  summary_.last_restart = path;
  // keep the newest restart_keep_ files
  auto files = restart_files(dir);
  for (std::size_t i = 0; i + static_cast<std::size_t>(restart_keep_) < files.size(); ++i) {
    std::error_code ec;
    fs::remove(files[i].second, ec);
  }
  summary_.output_seconds += clock.seconds();
  log::get("coupling")->debug("restart file {} ({:.3f} s)", path.string(), clock.seconds());
}

void CaseRun::read_restart_file(const fs::path& path, Progress& progress) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error("cannot read restart file " + path.string());
  BinaryReader in(file, path.string());
  std::string magic;
  try {
    in.read(magic);
  } catch (const Error&) {
  }
  if (magic != kMagic) throw Error(path.string() + " is not a partita restart file");
  // Every section against its CRC-32 before any value is used. A file of an older format has
  // no table: its version, when readable, says so more plainly than the missing table.
  try {
    in.verify_checksums();
  } catch (const Error&) {
    std::uint32_t version = 0;
    try {
      in.read(version);
    } catch (const Error&) {
    }
    if (version != 0 && version < kVersion)
      throw Error(fmt::format(
          "{} has restart format version {}; this partita reads version {} (resume with the "
          "partita that wrote it)",
          path.string(), version, kVersion));
    throw;
  }
  const auto version = in.get<std::uint32_t>();
  const auto order = in.get<std::uint32_t>();
  if (order != kByteOrder)
    throw Error(path.string() + " was written on a machine of another byte order");
  if (version != kVersion)
    throw Error(
        fmt::format("{} has restart format version {}; this partita reads version {} "
                    "(resume with the partita that wrote it)",
                    path.string(), version, kVersion));
  SavedRun read;
  read.pairs.resize(energy_pairs_.size());
  read.monitors.resize(monitors_.size());
  // the name, identity and window first: a file of another case is named as such, not as data
  // out of place (serialize_case() holds what the rest depends on)
  StateArchive ar(in);
  read.serialize_case(ar);
  if (read.name != name_ || read.identity != identity_)
    throw Error(fmt::format(
        "{} was written by {} whose participants or coupling differ from this case '{}': a run "
        "resumes only with the same participants and coupling sections (time and output may "
        "change)",
        path.string(), read.name == name_ ? "a version of the case" : "case '" + read.name + "'",
        name_));
  if (read.window_size != window_size_)
    throw Error(fmt::format("{} was written with time.window = {:.17g} s; this case has {:.17g} s",
                            path.string(), read.window_size, window_size_));
  read.serialize_state(ar);
  if (read.progress.windows_done < 0 || read.progress.frame < 0 ||
      !std::isfinite(read.progress.next_output))
    in.fail("a window count, a frame count and an output time");
  if (read.monitors.size() != monitors_.size())
    in.fail(fmt::format("{} monitors (found {})", monitors_.size(), read.monitors.size()));
  for (std::size_t i = 0; i < monitors_.size(); ++i)
    if (read.monitors[i].first != monitors_[i].name)
      in.fail("the monitor '" + monitors_[i].name + "'");
  // the energy balance's columns as the run started (a run that started without an energy
  // section starts its balance here: its initial value is then this window's)
  const auto header = [](const std::string& text) { return text.substr(0, text.find('\n')); };
  if (energy_ && !read.energy_csv.empty() && header(read.energy_csv) != header(energy_csv_.text()))
    throw Error(fmt::format(
        "{}: the run started with another energy section (energy.csv columns: {}; now: {}): "
        "resume with the energy section it started with",
        path.string(), header(read.energy_csv), header(energy_csv_.text())));
  scheme_->serialize(ar);
  const auto participants = in.get<std::uint64_t>();
  if (participants != participants_.size())
    in.fail(fmt::format("{} participants (found {})", participants_.size(), participants));
  for (auto& p : participants_) {
    in.expect_section("participant " + p->name());
    p->read_restart(in);
  }
  in.expect_section("end");
  if (read.progress.windows_done >= window_count_)
    throw Error(fmt::format(
        "{}: the restart point is window {} (t = {:.6g} s), and the case ends there (window "
        "{}): nothing to continue; raise time.end, e.g. --set time.end={:.6g}",
        path.string(), read.progress.windows_done,
        static_cast<double>(read.progress.windows_done) * window_size_, window_count_,
        2.0 * static_cast<double>(read.progress.windows_done) * window_size_));

  // Accepted: now the run's state and its files.
  progress = read.progress;
  summary_.iterations = static_cast<long>(read.iterations);
  summary_.unconverged_windows = static_cast<long>(read.unconverged_windows);
  summary_.max_window_iterations = read.max_window_iterations;
  summary_.imbalance_warnings = static_cast<long>(read.imbalance_warnings);
  summary_.energy_warnings = static_cast<long>(read.energy_warnings);
  summary_.windows = read.progress.windows_done;
  for (std::size_t i = 0; i < energy_pairs_.size(); ++i) {
    energy_pairs_[i].last_a = read.pairs[i].last_a;
    energy_pairs_[i].last_b = read.pairs[i].last_b;
    energy_pairs_[i].passed = read.pairs[i].passed;
    energy_pairs_[i].over = read.pairs[i].over;
  }
  coupling_csv_.restore_text(std::move(read.coupling_csv));
  for (std::size_t i = 0; i < monitors_.size(); ++i)
    monitors_[i].csv.restore_text(std::move(read.monitors[i].second));
  summary_.energy_balance_warnings = static_cast<long>(read.energy_balance_warnings);
  summary_.max_energy_balance_error = read.max_energy_balance_error;
  summary_.max_energy_balance_time = read.max_energy_balance_time;
  summary_.max_energy_balance_window = read.max_energy_balance_window;
  summary_.energy_balance_uncounted = static_cast<long>(read.energy_balance_uncounted);
  if (energy_ && !read.energy_csv.empty()) {
    energy_->restore(read.energy_started != 0, read.energy_initial);
    energy_csv_.restore_text(std::move(read.energy_csv));
  }
  for (auto& [series, entries] : read.pvds) pvd(series).restore_entries(std::move(entries));
}

void CaseRun::check_window(std::int64_t window, double time, bool after_audit) {
  for (const auto& e : exchanges_) {
    const Exchange& x = *e;
    if (after_audit) {
      const auto a = std::find(audited_.begin(), audited_.end(), &x);
      if (a != audited_.end() && audit_finite_[static_cast<std::size_t>(a - audited_.begin())])
        continue;  // sent and received both summed to finite totals in audit_balance()
    }
    for (const bool sent : {true, false}) {
      const Eigen::MatrixXd* side = sent ? &x.sent() : &x.received();
      // One vectorised pass per window; the count below only runs on the way to the error.
      if (all_finite(*side)) continue;
      const Eigen::Index bad = side->size() - side->array().isFinite().count();
      throw Error(fmt::format(
          "window {} (t = {:.6g} s): {} {} non-finite values ({} of {}) of '{}' on {}.{}: the "
          "run is diverging; reduce time.window or the substep size, add damping, or check the "
          "materials and loads of '{}'",
          window, time, sent ? "participant '" + e->from().name() + "' sent" : "the mapping gave",
          "", bad, side->size(), e->data(), sent ? e->from().name() : e->to().name(),
          sent ? e->from_mesh() : e->to_mesh(), e->from().name()));
    }
  }
  for (const auto& p : participants_) {
    Stopwatch clock;  // the solver's own work: its time, not the core's
    const std::string why = p->check_state();
    p->add_seconds(clock.seconds());
    if (!why.empty())
      throw Error(fmt::format("window {} (t = {:.6g} s): participant '{}': {}", window, time,
                              p->name(), why));
  }
}

const std::vector<double>& CaseRun::audit_balance() {
  if (audit_bounds_.size() != audited_.size()) {
    // Once: for a mapper with an explicit operator W >= 0, u = W^T omega (omega: the target's
    // weights, or 1 for a sum) bounds what can arrive: sum_q omega_q |r_q| <= sum_i u_i |s_i|.
    audit_bounds_.assign(audited_.size(), Eigen::VectorXd());
    for (std::size_t i = 0; i < audited_.size(); ++i) {
      const Exchange* e = audited_[i];
      if (!e->mapper()) continue;
      const Eigen::VectorXd omega = e->spec().kind == DataKind::extensive
                                        ? Eigen::VectorXd::Ones(e->target_mesh().size())
                                        : Eigen::VectorXd(e->target_mesh().weights());
      Eigen::VectorXd u;
      if (e->mapper()->arrival_bound(omega, u)) audit_bounds_[i] = std::move(u);
    }
  }
  imbalance_.resize(audited_.size());
  audit_finite_.resize(audited_.size());
  for (std::size_t i = 0; i < audited_.size(); ++i) {
    const Exchange* e = audited_[i];
    const bool extensive = e->spec().kind == DataKind::extensive;
    const Eigen::VectorXd* u = audit_bounds_[i].size() > 0 ? &audit_bounds_[i] : nullptr;
    double ss = 0.0, bound = 0.0, sr = 0.0, unused = 0.0;
    totals(e->sent(), e->source_mesh(), extensive, true, u, audit_sent_, audit_norm_, ss, bound);
    // scale = max(|sent|, |received|) (totals of the magnitudes). Where the bound shows
    // |received| <= |sent| (1 + 1e-6), the received lengths (a square root each) are not
    // summed and the scale is |sent|: low by at most 1e-6 of itself. (The tolerance is above
    // round-off: the cell areas of an STL in float32 and the FE face's quadrature weights
    // differ in their sums by about 2e-8.)
    const bool bounded = u && bound <= ss * (1.0 + 1e-6);
    totals(e->received(), e->target_mesh(), extensive, !bounded, nullptr, audit_received_,
           audit_norm_, sr, unused);
    // A NaN or an infinity among the values makes its total NaN or infinite (weights are finite
    // and >= 0; 0 times an infinity is NaN): finite totals let check_window() skip the values.
    audit_finite_[i] = std::isfinite(audit_sent_.sum()) && std::isfinite(audit_received_.sum());
    const double scale = bounded ? ss : std::max(ss, sr);
    imbalance_[i] = scale > 0.0 ? (audit_received_ - audit_sent_).norm() / scale : 0.0;
  }
  return imbalance_;
}

CaseRun::EnergyAudit CaseRun::audit_energy(const EnergyPair& pair) const {
  EnergyAudit a;
  for (const auto& m : pair.a_meshes) a.on_a += pair.a->interface_work(m).value_or(0.0);
  for (const auto& m : pair.b_meshes) a.on_b += pair.b->interface_work(m).value_or(0.0);
  return a;
}

double CaseRun::coupling_created() const {
  double created = 0.0;
  for (const auto& p : energy_pairs_) created += audit_energy(p).created();
  return created;
}

}  // namespace partita::run
