#pragma once
// A data mapper between two non-matching meshes: computed once from the source and target
// meshes (again on demand when a mesh moves), then applied many times.
//
//   consistent:   out = W in,   W (target x source), rows sum to 1: interpolates intensive
//                 quantities (displacement, traction); a constant field is reproduced exactly.
//   conservative: out = W^T in, W built in the opposite direction (source x target), consistent:
//                 distributes extensive quantities (force); the column sums of W^T are 1, so
//                 the total is preserved exactly.
//
// Call order: compute(from, to) once (and again whenever a mesh moved or changed), then
// map(in, out) any number of times. map() checks that `in` has one row per point of `from`.
//
// Mappers are chosen by name from the case file through a Registry<MapperFactory> filled by
// register_mappers(); the `mapper` node is a plain name (`mapper: nearest-projection`) or a map
// with `type` and the mapper's options (`mapper: {type: rbf, support_radius: 2.0e-3}`).
// create_mapper() does the lookup ("did you mean") and calls the factory.

#include <functional>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "partita/interface/config.hpp"
#include "partita/interface/mesh.hpp"
#include "partita/interface/registry.hpp"

namespace partita::coupling {

enum class Constraint { consistent, conservative };

/// "consistent" / "conservative".
const char* to_string(Constraint c);

class Mapper {
 public:
  virtual ~Mapper() = default;
  /// Build the mapping from `from` (source) to `to` (target).
  virtual void compute(const Mesh& from, const Mesh& to) = 0;
  /// Map values: in is from.size() x C, out becomes to.size() x C.
  virtual void map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const = 0;
  virtual Constraint constraint() const = 0;
  /// Registered name, for messages and the summary.
  virtual std::string name() const = 0;
  /// The balance audit's bound: for a mapper whose map() is out = W in with an explicit W >= 0,
  /// u = W^T omega (then sum_q omega_q |out_q| <= sum_i u_i |in_i| for any in) and true; false
  /// where the mapper has no such operator (the default: the audit then measures both sides).
  virtual bool arrival_bound(const Eigen::VectorXd& omega, Eigen::VectorXd& u) const {
    (void)omega;
    (void)u;
    return false;
  }

  /// Sizes and names of the meshes of the last compute() (-1 / "" before the first).
  Eigen::Index source_size() const { return source_size_; }
  Eigen::Index target_size() const { return target_size_; }
  const std::string& source_name() const { return source_name_; }
  const std::string& target_name() const { return target_name_; }

 protected:
  /// For implementations: remember the meshes of compute() (for the checks of map()).
  void set_meshes(const Mesh& from, const Mesh& to);
  /// For implementations: throw partita::Error unless compute() ran and `in` has one row per
  /// source point.
  void check_input(const Eigen::MatrixXd& in) const;

 private:
  Eigen::Index source_size_ = -1;
  Eigen::Index target_size_ = -1;
  std::string source_name_;
  std::string target_name_;
};

/// What a mapper factory receives: the exchange's mapper options and the constraint that
/// follows from the data kind (intensive -> consistent, extensive -> conservative) or from the
/// case file's explicit `constraint:` key.
struct MapperContext {
  config::Node config;  ///< the exchange's `mapper` node (a name, or a map with `type` and options)
  Constraint constraint = Constraint::consistent;
};

using MapperFactory = std::function<std::unique_ptr<Mapper>(const MapperContext&)>;

/// The mapper's name in a `mapper` node: the scalar itself, or the map's `type`.
/// Throws partita::Error at the node if it is neither.
std::string mapper_type(const config::Node& node);

/// Look up the mapper named by `context.config` (an unknown name fails at the node, listing the
/// known names and the nearest) and create it.
std::unique_ptr<Mapper> create_mapper(const Registry<MapperFactory>& registry,
                                      const MapperContext& context);

/// For factories: the options of the mapper node validated against `spec` (defaults filled in).
/// A plain-name node gives an empty map with the defaults; if `spec` has required keys, that
/// fails at the node and shows how to write the map form.
config::Node mapper_options(const config::Node& node,
                            const std::shared_ptr<const config::Spec>& spec);

}  // namespace partita::coupling
