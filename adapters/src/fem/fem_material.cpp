// The FEM participant's material (fem_material.hpp): its spec, made from the material-law
// registry, and the law the case's values make.

#include "fem_material.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fem_rupture.hpp"
#include "partita/adapters/material_laws.hpp"
#include "partita/fem/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::adapters {

namespace {

using config::Node;
using config::Spec;
using fem::MaterialLawEntry;
using fem::MaterialParameter;

std::string join(const std::vector<std::string>& names, const char* last = ", ") {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i)
    s += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return s;
}

// The laws of the registry that declare `key`.
std::vector<std::string> laws_taking(const fem::MaterialLawRegistry& laws, const std::string& key) {
  std::vector<std::string> names;
  for (const auto& e : laws.entries())
    if (e.find(key) != nullptr) names.push_back(e.name);
  return names;
}

// One key of the section: every law that declares it, and what the spec says of it.
struct Key {
  const MaterialParameter* first = nullptr;  // the first declaration: unit, doc, typical, table
  std::vector<std::string> laws;
  // the loosest of the declarations' ranges (each law's own range is checked when built)
  double min = 0.0, max = 0.0;
  bool min_exclusive = false, max_exclusive = false;
  bool required_by_all = true;  // required without a default by every law that declares it
};

// A number parameter as a real key of `spec`.
config::Param& declare(Spec& spec, const MaterialParameter& d, std::string doc, double min,
                       bool min_exclusive, double max, bool max_exclusive) {
  config::Param& key = spec.real(d.name, std::move(doc));
  if (!d.unit.empty()) key.unit(d.unit);
  if (std::isfinite(min)) key.min(min, min_exclusive);
  if (std::isfinite(max)) key.max(max, max_exclusive);
  if (d.typical_range) key.typical(d.typical_range->first, d.typical_range->second, d.typical_what);
  if (d.default_value) key.def(*d.default_value);
  return key;
}

std::shared_ptr<Spec> make_material_spec(const fem::MaterialLawRegistry& laws) {
  std::vector<std::string> names, described;
  std::vector<std::pair<std::string, Key>> keys;  // in the order the laws declare them
  for (const auto& entry : laws.entries()) {
    names.push_back(entry.name);
    described.push_back(entry.name + " (" + entry.doc + ")");
    for (const auto& d : entry.parameters) {
      auto it = std::find_if(keys.begin(), keys.end(), [&](const auto& k) { return k.first == d.name; });
      if (it == keys.end()) {
        Key k;
        k.first = &d;
        k.min = d.min;
        k.max = d.max;
        k.min_exclusive = d.min_exclusive;
        k.max_exclusive = d.max_exclusive;
        keys.emplace_back(d.name, k);
        it = keys.end() - 1;
      } else {
        Key& k = it->second;
        if (d.min < k.min || (d.min == k.min && !d.min_exclusive)) {
          k.min_exclusive = d.min < k.min ? d.min_exclusive : false;
          k.min = d.min;
        }
        if (d.max > k.max || (d.max == k.max && !d.max_exclusive)) {
          k.max_exclusive = d.max > k.max ? d.max_exclusive : false;
          k.max = d.max;
        }
      }
      it->second.laws.push_back(entry.name);
      it->second.required_by_all =
          it->second.required_by_all && d.is_required && !d.default_value;
    }
  }

  auto material = std::make_shared<Spec>(
      "material",
      "the material: a law of the FE solver (built in, or added by a plugin) and its "
      "parameters; keys that some laws only take say which");
  if (!names.empty())
    material->choice("model", join(described, " or "), names).def(names.front());
  for (const auto& [name, k] : keys) {
    const MaterialParameter& d = *k.first;
    const bool in_all = k.laws.size() == names.size();
    const std::string doc = in_all ? d.doc : join(k.laws) + ": " + d.doc;
    if (d.is_table()) {
      auto row = std::make_shared<Spec>(d.row_name.empty() ? d.name + "_row" : d.row_name,
                                        d.row_doc.empty() ? "a row of " + d.name : d.row_doc);
      for (const auto& c : d.columns)
        declare(*row, c, c.doc, c.min, c.min_exclusive, c.max, c.max_exclusive).required();
      material->list(d.name, doc, row);
    } else {
      config::Param& key =
          declare(*material, d, doc, k.min, k.min_exclusive, k.max, k.max_exclusive);
      if (in_all && k.required_by_all) key.required();
    }
  }
  material->section("failure", "rupture (j2-plasticity)", fem_failure_spec());
  return material;
}

std::shared_ptr<Spec>& material_spec() {
  static std::shared_ptr<Spec> spec = make_material_spec(material_laws());
  return spec;
}

// A value outside the range the chosen law declares (the spec's range is the loosest of the
// laws that share the key).
[[noreturn]] void out_of_range(const Node& at, const MaterialLawEntry& entry,
                               const MaterialParameter& d, double v) {
  at.fail(fmt::format("value {:.6g}{} is out of range for material model {}; allowed: {}", v,
                      d.unit.empty() ? "" : " " + d.unit, entry.name, d.range_text()));
}

// The case's values of the law's parameters, read once (numbers in SI; absent ones left to the
// entry's defaults); a parameter the law requires and the case lacks is an error at the section.
fem::MaterialParameters read_parameters(const MaterialLawEntry& entry, const Node& mat) {
  fem::MaterialParameters p;
  for (const auto& d : entry.parameters) {
    if (!mat.has(d.name)) {
      if (d.is_required && !d.default_value)
        mat.fail(fmt::format("material model {} needs '{}' ({})", entry.name, d.name, d.doc));
      continue;
    }
    if (d.is_table()) {
      fem::MaterialParameters::Table rows;
      for (const Node& item : mat[d.name].items()) {
        std::vector<double> row;
        for (const auto& c : d.columns) {
          const double v = item.real(c.name);
          if (!c.allows(v)) out_of_range(item[c.name], entry, c, v);
          row.push_back(v);
        }
        rows.push_back(std::move(row));
      }
      p.set_table(d.name, std::move(rows));
    } else {
      const double v = mat.real(d.name);
      if (!d.allows(v)) out_of_range(mat[d.name], entry, d, v);
      p.set(d.name, v);
    }
  }
  return p;
}

// Keys of other laws given to this one: a warning, for they are ignored.
void warn_foreign_keys(const MaterialLawEntry& entry, const Node& mat) {
  for (const std::string& key : mat.keys()) {
    if (key == "model" || key == "failure" || entry.find(key) != nullptr) continue;
    const auto takers = laws_taking(material_laws(), key);
    if (takers.empty()) continue;  // not a law's key (the spec refused unknown ones)
    const Node at = mat[key];
    log::get("adapters")
        ->warn("{}: key '{}': material model {} does not take {} (a parameter of {}); it is "
               "ignored",
               at.location().str(), at.path(), entry.name, key, join(takers));
  }
}

// "; a number without a unit is in Pa: write the unit, e.g. youngs_modulus: 210 GPa" when the
// key is a bare number of a parameter with a unit ("" otherwise); the prefix shown is the first
// of G, M, k that brings the value into the parameter's typical range (G without one).
std::string unit_hint(const Node& at, const std::string& key, const MaterialParameter* d) {
  if (d == nullptr || d->unit.empty() || !at.is_scalar()) return "";
  const std::string text = at.yaml().Scalar();
  const auto bare = config::parse_quantity(text, "");
  if (!bare) return "";
  std::string prefix = "G";
  if (d->typical_range) {
    for (const auto& [p, factor] : {std::pair{"G", 1e9}, {"M", 1e6}, {"k", 1e3}}) {
      const double v = *bare * factor;
      if (v >= d->typical_range->first && v <= d->typical_range->second) {
        prefix = p;
        break;
      }
    }
  }
  return fmt::format("; a number without a unit is in {}: write the unit, e.g. {}: {} {}{}",
                     d->unit, key, text, prefix, d->unit);
}

// A rule between the parameters broken: the error at the key it is about (the cell of a table),
// naming the lines of the other keys the rule reads.
[[noreturn]] void fail_at(const MaterialLawEntry& entry, const Node& mat,
                          const fem::MaterialParameterIssue& issue) {
  std::string message = issue.message;
  for (const auto& key : issue.related) {
    if (!mat.has(key)) continue;
    message += fmt::format("; {} is at line {}", key, mat[key].location().line);
    message += unit_hint(mat[key], key, entry.find(key));
  }
  // (a config::Node is not reassigned: assigning a YAML::Node writes into the document)
  if (issue.parameter.empty() || !mat.has(issue.parameter)) mat.fail(message);
  const Node parameter = mat[issue.parameter];
  if (issue.row < 0 || static_cast<std::size_t>(issue.row) >= parameter.size())
    parameter.fail(message);
  const Node row = parameter[static_cast<std::size_t>(issue.row)];
  if (issue.column.empty() || !row.has(issue.column)) row.fail(message);
  row[issue.column].fail(message);
}

}  // namespace

std::shared_ptr<config::Spec> fem_material_spec() {
  return material_spec();
}

void refresh_fem_material_spec() {
  *material_spec() = *make_material_spec(material_laws());
}

fem::Model build_fem_model(fem::Mesh mesh, const config::Node& mat) {
  const MaterialLawEntry& entry = material_laws().get(mat.string("model"));
  warn_foreign_keys(entry, mat);
  std::shared_ptr<const fem::MaterialLaw> law;
  fem::MaterialParameters p;
  try {
    p = entry.completed(read_parameters(entry, mat));
  } catch (const fem::Error& error) {
    mat.fail(error.what());
  }
  if (auto issue = entry.issue(p)) fail_at(entry, mat, *issue);
  try {
    law = entry.factory(p);
  } catch (const fem::Error& error) {
    mat.fail(error.what());
  }
  if (!law) mat.fail("material model " + entry.name + ": its factory made no law");
  // the one material of the model: the law (a linear-elastic law keeps the linear path)
  fem::Model model(std::move(mesh));
  model.set_material_law(std::move(law));
  model.set_failure_criterion(build_failure_criterion(mat));
  return model;
}

}  // namespace partita::adapters
