#include "partita/coupling/implicit_scheme.hpp"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "partita/coupling/registries.hpp"
#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::coupling {

namespace {
Eigen::Map<const Eigen::VectorXd> flat(const Eigen::MatrixXd& m) {
  return {m.data(), m.size()};
}
}  // namespace

ImplicitScheme::ImplicitScheme(std::vector<Participant*> participants,
                               std::vector<Exchange*> exchanges, Options options,
                               std::vector<std::unique_ptr<ConvergenceMeasure>> measures,
                               std::unique_ptr<Acceleration> acceleration,
                               std::vector<Exchange*> accelerated)
    : CouplingScheme(std::move(participants), std::move(exchanges)),
      options_(options),
      measures_(std::move(measures)),
      acceleration_(std::move(acceleration)),
      accelerated_(std::move(accelerated)) {
  if (measures_.empty())
    throw Error("scheme '" + name() + "' needs at least one convergence measure");
  if (options_.max_iterations < 1) throw Error("max_iterations must be >= 1");
  for (const auto& m : measures_) {
    std::vector<Exchange*> ex;
    for (Exchange* e : exchanges_)
      if (e->data() == m->data()) ex.push_back(e);
    if (ex.empty())
      throw Error("convergence measure on '" + m->data() + "': no exchange carries that data");
    measured_.push_back(std::move(ex));
  }
  if (acceleration_ && accelerated_.empty()) {
    for (Exchange* e : exchanges_)
      if (!options_.serial || &e->from() == participants_.back()) accelerated_.push_back(e);
  }
  if (options_.serial)
    for (Exchange* e : accelerated_)
      if (&e->from() != participants_.back())
        throw Error("scheme implicit-serial: exchange " + e->label() +
                    " is written by participant '" + e->from().name() +
                    "', which is not last in the order; "
                    "a serial scheme accelerates only what the last participant writes");
}

std::vector<std::pair<std::string, std::string>> ImplicitScheme::residual_columns() const {
  std::vector<std::pair<std::string, std::string>> c;
  for (std::size_t i = 0; i < measures_.size(); ++i) {
    const auto& m = measures_[i];
    c.emplace_back(m->name() + " " + m->data(),
                   m->dimensionless() ? "" : measured_[i].front()->spec().unit);
  }
  return c;
}

void ImplicitScheme::stack(const std::vector<Exchange*>& ex, bool previous,
                           Eigen::VectorXd& out) const {
  Eigen::Index n = 0;
  for (const Exchange* e : ex) n += (previous ? e->previous() : e->combined()).size();
  out.resize(n);
  Eigen::Index at = 0;
  for (const Exchange* e : ex) {
    const Eigen::MatrixXd& m = previous ? e->previous() : e->combined();
    out.segment(at, m.size()) = flat(m);
    at += m.size();
  }
}

void ImplicitScheme::compute_weights() {
  // w_i = 1 / |x_i| per field, x_i from the previous window (else this iteration's values)
  Eigen::Index n = 0;
  for (const Exchange* e : accelerated_) n += e->previous().size();
  weights_.resize(n);
  Eigen::Index at = 0;
  for (const Exchange* e : accelerated_) {
    double norm = e->previous().norm();
    if (!(norm > 0.0)) norm = e->combined().norm();
    if (!(norm > 0.0)) norm = 1.0;
    weights_.segment(at, e->previous().size()).setConstant(1.0 / norm);
    at += e->previous().size();
  }
}

WindowReport ImplicitScheme::run_window(const TimeWindow& window) {
  WindowReport report;
  for (Participant* p : participants_) p->save_checkpoint();
  for (auto& m : measures_) m->new_window();
  Eigen::VectorXd previous, current, next;
  for (int k = 1;; ++k) {
    for (Exchange* e : exchanges_) e->remember_previous();
    std::set<const Exchange*> sent;
    if (options_.serial) {
      for (Participant* p : participants_) {
        run_participant(*p, window);
        if (p != participants_.back()) {
          send_outputs(*p);
          for (Exchange* e : exchanges_)
            if (&e->from() == p) sent.insert(e);
        }
      }
    } else {
      run_all(window);
    }
    for (Participant* p : participants_) p->finish_window();
    // convergence: every measure on (previous iterate, new values) of its field
    bool converged = true;
    report.residuals.clear();
    for (std::size_t i = 0; i < measures_.size(); ++i) {
      stack(measured_[i], true, previous);
      stack(measured_[i], false, current);
      measures_[i]->measure(previous, current);
      converged = converged && measures_[i]->converged();
      report.residuals.push_back(measures_[i]->value());
    }
    report.iterations = k;
    if (k == 1 && acceleration_) compute_weights();
    if (converged || k >= options_.max_iterations) {
      report.converged = converged;
      if (!converged) {
        std::string values;
        for (const auto& m : measures_)
          values += fmt::format("{}{} {} {:.3g} (limit {:.3g})", values.empty() ? "" : ", ",
                                m->name(), m->data(), m->value(), m->limit());
        const std::string msg = fmt::format(
            "window {} (t = {:.6g} s) did not converge in {} iterations "
            "(max_iterations): {}",
            window.index(), window.end(), k, values);
        if (options_.on_max_iterations == OnMaxIterations::error)
          throw Error(msg +
                      "; raise max_iterations, use a stronger acceleration, or set "
                      "on_max_iterations: accept");
        log::get("coupling")->warn("{}; accepting it (on_max_iterations: accept)", msg);
      }
      if (acceleration_) {
        stack(accelerated_, true, previous);
        stack(accelerated_, false, current);
        acceleration_->window_converged(previous, current, weights_);
      }
      for (Exchange* e : exchanges_) {
        if (sent.count(e)) continue;
        e->sent() = e->combined();
        e->transmit();
      }
      return report;
    }
    if (acceleration_) {
      // x_{k+1} = A(x_k, H(x_k)) on the accelerated fields
      stack(accelerated_, true, previous);
      stack(accelerated_, false, current);
      acceleration_->accelerate(previous, current, weights_, next);
      Eigen::Index at = 0;
      for (Exchange* e : accelerated_) {
        Eigen::MatrixXd& s = e->sent();
        s.resize(e->combined().rows(), e->combined().cols());
        Eigen::Map<Eigen::VectorXd>(s.data(), s.size()) = next.segment(at, s.size());
        at += s.size();
        e->transmit();
        sent.insert(e);
      }
    }
    for (Exchange* e : exchanges_) {
      if (sent.count(e)) continue;
      e->sent() = e->combined();
      e->transmit();
    }
    for (Participant* p : participants_) p->restore_checkpoint();
  }
}

// The exchanges, the acceleration's name (a reader checks it is its own), its history.
void ImplicitScheme::serialize(StateArchive& ar) {
  CouplingScheme::serialize(ar);
  const std::string mine = acceleration_ ? acceleration_->name() : "none";
  std::string stored = mine;
  ar.io(stored);
  if (stored != mine) ar.fail("the acceleration '" + mine + "', found '" + stored + "'");
  if (acceleration_) acceleration_->serialize(ar);
}

namespace {

std::unique_ptr<CouplingScheme> create(const SchemeContext& c, bool serial) {
  const std::string scheme = serial ? "implicit-serial" : "implicit-parallel";
  const config::Node& cfg = c.config;
  const Registries& reg = *c.registries;
  std::vector<std::string> data_names;
  for (const Exchange* e : c.exchanges)
    if (std::find(data_names.begin(), data_names.end(), e->data()) == data_names.end())
      data_names.push_back(e->data());
  auto check_data = [&](const config::Node& n) {
    const std::string d = n.as_string();
    if (std::find(data_names.begin(), data_names.end(), d) == data_names.end())
      n.fail("no exchange carries data '" + d + "'; exchanged data: " + join_names(data_names) +
             did_you_mean(d, data_names));
  };

  std::vector<std::unique_ptr<ConvergenceMeasure>> measures;
  const config::Node conv = cfg["convergence"];
  if (!conv.defined() || (conv.is_sequence() && conv.size() == 0))
    cfg.fail("scheme '" + scheme +
             "' needs a convergence measure: add key 'convergence', e.g. "
             "convergence: [{type: relative, data: " +
             (data_names.empty() ? std::string("pressure") : data_names.front()) +
             ", limit: 1.0e-5}]; known measures: " + join_names(reg.convergence_measures.names()));
  for (const config::Node& item : conv.items()) {
    if (!item.is_map() || !item.has("type"))
      item.fail(
          "a convergence measure is a map with 'type', 'data' and 'limit', e.g. {type: relative, "
          "data: "
          "pressure, limit: 1.0e-5}; known types: " +
          join_names(reg.convergence_measures.names()));
    const auto& entry = reg.convergence_measures.get(item["type"]);
    const config::Node v = entry.spec ? item.validated(entry.spec) : item;
    check_data(v["data"]);
    measures.push_back(entry.factory(v));
  }

  std::unique_ptr<Acceleration> acceleration;
  std::vector<Exchange*> accelerated;
  const config::Node acc = cfg["acceleration"];
  if (acc.defined()) {
    config::Node a = acc;
    if (acc.is_scalar())
      a = config::Node(YAML::Load("{type: " + acc.as_string() + "}"),
                       std::make_shared<const std::string>(acc.file()), acc.path());
    if (!a.is_map() || !a.has("type"))
      acc.fail(
          "expected an acceleration name or a map with 'type' (e.g. {type: iqn-ils, "
          "initial_relaxation: "
          "0.01}); known: " +
          join_names(reg.accelerations.names()));
    const auto& entry = reg.accelerations.get(acc.is_scalar() ? acc : a["type"]);
    const config::Node v = entry.spec ? a.validated(entry.spec) : a;
    acceleration = entry.factory(v);
    if (v.has("data")) {
      for (const config::Node& d : v["data"].items()) {
        check_data(d);
        for (Exchange* e : c.exchanges)
          if (e->data() == d.as_string()) {
            if (serial && &e->from() != c.participants.back())
              d.fail("a serial scheme accelerates only what the last participant ('" +
                     c.participants.back()->name() + "') writes; '" + e->data() +
                     "' is written by '" + e->from().name() + "'");
            accelerated.push_back(e);
          }
      }
    }
  }
  ImplicitScheme::Options o;
  o.serial = serial;
  o.max_iterations = static_cast<int>(cfg.integer("max_iterations"));
  o.on_max_iterations =
      cfg.string("on_max_iterations") == "error" ? OnMaxIterations::error : OnMaxIterations::accept;
  return std::make_unique<ImplicitScheme>(c.participants, c.exchanges, o, std::move(measures),
                                          std::move(acceleration), std::move(accelerated));
}

}  // namespace

std::unique_ptr<CouplingScheme> ImplicitScheme::create_serial(const SchemeContext& context) {
  return create(context, true);
}
std::unique_ptr<CouplingScheme> ImplicitScheme::create_parallel(const SchemeContext& context) {
  return create(context, false);
}

}  // namespace partita::coupling
