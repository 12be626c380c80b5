#pragma once
#include <vector>

#include "partita/fem/element_type.hpp"
#include "partita/fem/face_type.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

struct VolumeRulePoint {
  Vec3 xi;
  double weight;
};
struct FaceRulePoint {
  Eigen::Vector2d xi;
  double weight;
};

// What a volume rule integrates: stiffness (grad N . D . grad N) or mass (N N).
enum class QuadratureUse { Stiffness, Mass };

// Gauss rules (weights sum to the reference volume / area):
//   Hex8 2x2x2 (both), Hex20 3x3x3 (both); Tet4 1 point (stiffness), 4 points degree 2 (mass);
//   Tet10 4 points degree 2 (stiffness), collapsed 4x4x4 Gauss-Legendre, exact to degree 7
//   (mass); Quad4 2x2, Quad8 3x3, Tri3 3 points degree 2, Tri6 6 points degree 4 (Dunavant).
const std::vector<VolumeRulePoint>& volume_rule(ElementType type, QuadratureUse use);
const std::vector<FaceRulePoint>& face_rule(FaceType type);
// The EAS Hex8's rule for a thin element: 2 x 2 Gauss points across and 6 Gauss points through
// the thin parametric direction `thin` (0: xi, 1: eta, 2: zeta). Six points integrate a fully
// plastic section's moment int |z| dz to +2 % (2 points: +15 %, 5 points: -5.5 %).
const std::vector<VolumeRulePoint>& layered_hex_rule(int thin);
// The reduced Hex8's rule (Hex8Formulation::Reduced): `points` Gauss points (2 or 6) on the
// line through the centre along the parametric direction `thin`, each weighted for the whole
// cross-section (4 w_k): one point in the plane, several through the thickness.
const std::vector<VolumeRulePoint>& thickness_line_rule(int thin, int points);

}  // namespace partita::fem
