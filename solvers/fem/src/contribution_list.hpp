#pragma once
// What the operators that take contributions (NonlinearOperator, LinearContributionOperator)
// share: adding one, and the tangent's sparsity pattern that follows from it.
#include <iterator>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/operator_contribution.hpp"

namespace partita::fem::detail {

// Appends `contribution` to `contributions`. One that couples nodes beyond the mesh's elements
// rebuilds `assembler` over the mesh's node adjacency plus every contribution's coupled node
// groups; after a tangent was assembled (`pattern_fixed`) that is refused. `owner` names the
// operator in messages.
inline void add_contribution(std::vector<std::unique_ptr<OperatorContribution>>& contributions,
                             std::unique_ptr<BlockAssembler>& assembler, const Mesh& mesh,
                             bool pattern_fixed, std::unique_ptr<OperatorContribution> contribution,
                             std::string_view owner) {
  if (!contribution) throw Error(std::string(owner) + ": a null contribution was added");
  auto groups = contribution->coupled_node_groups();
  if (!groups.empty()) {
    if (pattern_fixed) {
      throw Error(std::string(owner) + ": contribution '" + std::string(contribution->name()) +
                  "' couples nodes beyond the mesh's elements and was added after a tangent was "
                  "assembled (add such contributions before the first implicit solve)");
    }
    for (const auto& c : contributions) {
      auto g = c->coupled_node_groups();
      groups.insert(groups.end(), std::make_move_iterator(g.begin()),
                    std::make_move_iterator(g.end()));
    }
    assembler = std::make_unique<BlockAssembler>(mesh, groups);
  }
  contributions.push_back(std::move(contribution));
}

}  // namespace partita::fem::detail
