#pragma once
// A parametric sweep declared in the case file: the same case run once per combination of the
// listed values (full factorial), each variant into its own folder, with a summary CSV of
// declared result quantities and one plot overlaying a monitor of every variant.
//
//   sweep:
//     parameters:
//       - {key: participants.granules.materials.glass.youngs_modulus,
//          values: [20 MPa, 200 MPa, 2 GPa], label: E}
//     results:
//       - {name: final_force, monitor: reaction, column: granules.plate.force_z, of: final}
//       - {name: peak_force,  monitor: reaction, column: granules.plate.force_z, of: max}
//     plot: {monitor: reaction, column: granules.plate.force_z}
//
// Variant folders are DIR/<label>=<value>[,<label>=<value>...] (value text without spaces);
// each holds the variant's run (its CSV and VTK files, log.txt and variant.yaml, the case as
// the variant ran it). DIR/sweep.csv has one row per variant: the values, the status (ok, or the
// error's first line), then each result. This class plans the variants and evaluates results;
// running them (processes, --jobs) is the caller's.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "partita/interface/config.hpp"

namespace partita::run {

class Sweep {
 public:
  struct Parameter {
    std::string key;                  ///< key path in the case, as --set takes it
    std::string label;                ///< folder and column name
    std::vector<std::string> values;  ///< YAML text of each value
    std::vector<SourceLocation> origins;  ///< where each value is in the case file
  };
  struct Result {
    std::string name, monitor, column, of;  ///< of: final | max | min | mean
  };
  struct Variant {
    std::string folder;                  ///< "<label>=<value>,..." (relative to the sweep folder)
    std::vector<std::string> overrides;  ///< "key=value" for partita run --set
    std::vector<std::string> values;     ///< one per parameter
  };

  /// The validated `sweep` section of the case `root` (throws partita::Error at the key: a key
  /// path that is not in the case file, with did-you-mean; two parameters that set the same key
  /// or one inside the other; a label that is not a plain name (it becomes a folder name); an
  /// empty value list; a result or plot that names no declared monitor or column). The values'
  /// types are checked by CaseRun (check) against the declaration of the key they set.
  Sweep(const config::Node& root);

  /// The schema of the `sweep` section (for the case schema and `partita docs`).
  static std::shared_ptr<const config::Spec> spec();

  const std::vector<Parameter>& parameters() const { return parameters_; }
  const std::vector<Result>& results() const { return results_; }
  /// Every combination, the first parameter varying slowest.
  const std::vector<Variant>& variants() const { return variants_; }
  /// The monitor and column overlaid in sweep.png ("" when no plot is declared).
  const std::string& plot_monitor() const { return plot_monitor_; }
  const std::string& plot_column() const { return plot_column_; }
  /// The x column of the plot ("": the monitor's time) and the scale factors of x and y.
  const std::string& plot_x() const { return plot_x_; }
  double plot_x_scale() const { return plot_x_scale_; }
  double plot_y_scale() const { return plot_y_scale_; }

  /// A result of one finished variant, read from its monitor CSV in `variant_dir`; NaN when the
  /// file or column is missing or has no rows.
  double evaluate(const Result& r, const std::filesystem::path& variant_dir) const;

  /// Write DIR/sweep.csv: one row per variant with its status ("ok" or an error text).
  void write_summary(const std::filesystem::path& dir,
                     const std::vector<std::string>& status) const;

 private:
  std::vector<Parameter> parameters_;
  std::vector<Result> results_;
  std::vector<Variant> variants_;
  std::string plot_monitor_, plot_column_, plot_x_;
  double plot_x_scale_ = 1.0, plot_y_scale_ = 1.0;
};

}  // namespace partita::run
