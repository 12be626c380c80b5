#include "partita/fem/gmsh_reader.hpp"

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// Line-oriented reader that knows where it is, for error messages "file:line: ...".
class LineReader {
 public:
  explicit LineReader(const std::string& path) : path_(path), in_(path) {
    if (!in_) throw Error(path + ": cannot open the mesh file");
  }
  // Next non-empty line; throws at end of file, saying what was expected.
  const std::string& next(const char* expected) {
    while (std::getline(in_, line_)) {
      ++number_;
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      if (line_.find_first_not_of(" \t") != std::string::npos) return line_;
    }
    throw Error(path_ + ":" + std::to_string(number_) + ": unexpected end of file; expected " +
                expected);
  }
  bool next_if_any() {
    while (std::getline(in_, line_)) {
      ++number_;
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      if (line_.find_first_not_of(" \t") != std::string::npos) return true;
    }
    return false;
  }
  const std::string& line() const { return line_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(path_ + ":" + std::to_string(number_) + ": " + what + " (line: '" +
                line_.substr(0, 80) + "')");
  }
  // Parses the current line as numbers; at least `min` of them.
  template <class T>
  std::vector<T> numbers(std::size_t min, const char* what) const {
    std::istringstream ss(line_);
    std::vector<T> v;
    T x;
    while (ss >> x) v.push_back(x);
    if (!ss.eof()) fail(std::string("expected only numbers in ") + what);
    if (v.size() < min) {
      fail(std::string("expected ") + std::to_string(min) + " numbers in " + what + ", found " +
           std::to_string(v.size()));
    }
    return v;
  }

 private:
  std::string path_;
  std::ifstream in_;
  std::string line_;
  std::size_t number_ = 0;
};

struct GmshType {
  int dim;
  int nodes;
};
// Gmsh element types this reader knows (others of dimension 2 or 3 are errors).
const std::map<int, GmshType> kTypes = {{15, {0, 1}}, {1, {1, 2}},   {8, {1, 3}},  {2, {2, 3}},
                                        {3, {2, 4}},  {9, {2, 6}},   {16, {2, 8}}, {4, {3, 4}},
                                        {5, {3, 8}},  {11, {3, 10}}, {17, {3, 20}}};

// partita node k = gmsh node kPerm[k]
constexpr std::array<int, 20> kHex20Perm = {0,  1, 2,  3,  4,  5,  6,  7,  8,  11,
                                            13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
constexpr std::array<int, 10> kTet10Perm = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};

void expect_end(LineReader& r, const std::string& section) {
  r.next(("$End" + section).c_str());
  if (r.line().rfind("$End" + section, 0) != 0) r.fail("expected $End" + section);
}

}  // namespace

Mesh read_gmsh(const std::string& path) {
  LineReader r(path);
  bool have_format = false;
  std::map<std::pair<int, int>, std::string> physical_names;         // (dim, tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_physicals;  // (dim, entity) -> tags
  Mesh mesh;
  std::unordered_map<std::size_t, std::size_t> node_index;  // gmsh tag -> index
  std::map<std::string, std::vector<std::size_t>> sets;
  bool have_nodes = false;

  auto group_name = [&](int dim, int tag) {
    auto it = physical_names.find({dim, tag});
    return it != physical_names.end() ? it->second
                                      : "group_" + std::to_string(dim) + "_" + std::to_string(tag);
  };
  auto node_of = [&](std::size_t tag) {
    auto it = node_index.find(tag);
    if (it == node_index.end())
      r.fail("element refers to node " + std::to_string(tag) + ", which is not in $Nodes");
    return it->second;
  };

  while (r.next_if_any()) {
    const std::string head = r.line().substr(0, r.line().find_first_of(" \t"));
    if (head.empty() || head[0] != '$')
      r.fail("expected a section header such as $MeshFormat, $Nodes, $Elements");
    const std::string section = head.substr(1);
    if (section == "MeshFormat") {
      r.next("the format line '4.1 0 8'");
      std::istringstream ss(r.line());
      std::string version;
      int file_type = -1, size = 0;
      ss >> version >> file_type >> size;
      if (version.rfind("4.1", 0) != 0) {
        r.fail("mesh format version " + version +
               " is not supported; allowed: 4.1 (gmsh -format msh41)");
      }
      if (file_type != 0)
        r.fail("binary .msh files are not supported; allowed: ASCII (file-type 0)");
      expect_end(r, section);
      have_format = true;
    } else if (!have_format) {
      r.fail("the file must start with $MeshFormat");
    } else if (section == "PhysicalNames") {
      r.next("the number of physical names");
      const auto n = r.numbers<long>(1, "$PhysicalNames count")[0];
      for (long i = 0; i < n; ++i) {
        r.next("a physical name line 'dim tag \"name\"'");
        std::istringstream ss(r.line());
        int dim = -1, tag = -1;
        ss >> dim >> tag;
        const auto q0 = r.line().find('"'), q1 = r.line().rfind('"');
        if (!ss || q0 == std::string::npos || q1 <= q0) r.fail("expected 'dim tag \"name\"'");
        physical_names[{dim, tag}] = r.line().substr(q0 + 1, q1 - q0 - 1);
      }
      expect_end(r, section);
    } else if (section == "Entities") {
      r.next("entity counts");
      const auto counts = r.numbers<long>(4, "$Entities counts (points curves surfaces volumes)");
      for (int dim = 0; dim < 4; ++dim) {
        for (long i = 0; i < counts[static_cast<std::size_t>(dim)]; ++i) {
          r.next("an entity line");
          const auto v = r.numbers<double>(dim == 0 ? 5 : 8, "an entity line");
          const std::size_t np_at = dim == 0 ? 4 : 7;
          const auto np = static_cast<std::size_t>(v[np_at]);
          if (v.size() < np_at + 1 + np)
            r.fail("entity line lists fewer physical tags than announced");
          std::vector<int> tags;
          for (std::size_t k = 0; k < np; ++k) tags.push_back(static_cast<int>(v[np_at + 1 + k]));
          entity_physicals[{dim, static_cast<int>(v[0])}] = tags;
        }
      }
      expect_end(r, section);
    } else if (section == "Nodes") {
      r.next("'numEntityBlocks numNodes minNodeTag maxNodeTag'");
      const auto h = r.numbers<long>(4, "the $Nodes header");
      for (long b = 0; b < h[0]; ++b) {
        r.next("a node block header 'entityDim entityTag parametric numNodesInBlock'");
        const auto bh = r.numbers<long>(4, "a node block header");
        if (bh[2] != 0)
          r.fail("parametric nodes are not supported; save without parametric coordinates");
        std::vector<std::size_t> tags;
        for (long k = 0; k < bh[3]; ++k) {
          r.next("a node tag");
          tags.push_back(static_cast<std::size_t>(r.numbers<long>(1, "a node tag")[0]));
        }
        for (long k = 0; k < bh[3]; ++k) {
          r.next("node coordinates 'x y z'");
          const auto x = r.numbers<double>(3, "node coordinates");
          node_index[tags[static_cast<std::size_t>(k)]] = mesh.add_node(Vec3(x[0], x[1], x[2]));
        }
      }
      if (static_cast<long>(mesh.num_nodes()) != h[1]) {
        r.fail("$Nodes announced " + std::to_string(h[1]) + " nodes but its blocks hold " +
               std::to_string(mesh.num_nodes()));
      }
      expect_end(r, section);
      have_nodes = true;
    } else if (section == "Elements") {
      if (!have_nodes) r.fail("$Elements before $Nodes");
      r.next("'numEntityBlocks numElements minElementTag maxElementTag'");
      const auto h = r.numbers<long>(4, "the $Elements header");
      int default_region = -1;
      for (long b = 0; b < h[0]; ++b) {
        r.next("an element block header 'entityDim entityTag elementType numElementsInBlock'");
        const auto bh = r.numbers<long>(4, "an element block header");
        const int dim = static_cast<int>(bh[0]), entity = static_cast<int>(bh[1]),
                  gtype = static_cast<int>(bh[2]);
        const auto it = kTypes.find(gtype);
        if (it == kTypes.end() || it->second.dim != dim) {
          if (dim <= 1) {  // unknown point/line types: skip the block
            for (long k = 0; k < bh[3]; ++k) r.next("an element line");
            continue;
          }
          r.fail("element type " + std::to_string(gtype) + " in a " + std::to_string(dim) +
                 "D block is not supported; allowed: 4 (tet4), 5 (hex8), 11 (tet10), 17 (hex20) "
                 "and faces 2 (tri3), 3 (quad4), 9 (tri6), 16 (quad8); use "
                 "Mesh.SecondOrderIncomplete = 1");
        }
        const int nn = it->second.nodes;
        const auto phys_it = entity_physicals.find({dim, entity});
        const std::vector<int> phys =
            phys_it != entity_physicals.end() ? phys_it->second : std::vector<int>{};
        int region = -1;
        if (dim == 3) {
          if (!phys.empty()) {
            region = mesh.add_region(group_name(3, phys[0]));
          } else {
            if (default_region < 0) default_region = mesh.add_region("default");
            region = default_region;
          }
        }
        for (long k = 0; k < bh[3]; ++k) {
          r.next("an element line 'tag node ...'");
          const auto v = r.numbers<long>(1, "an element line (tag and its nodes)");
          if (v.size() != 1 + static_cast<std::size_t>(nn)) {
            r.fail("element of gmsh type " + std::to_string(gtype) + " needs " +
                   std::to_string(nn) + " nodes, found " + std::to_string(v.size() - 1));
          }
          if (dim <= 1) continue;
          std::array<std::size_t, kMaxElementNodes> g{};
          for (int a = 0; a < nn; ++a) g[a] = node_of(static_cast<std::size_t>(v[1 + a]));
          std::array<std::size_t, kMaxElementNodes> ids{};
          for (int a = 0; a < nn; ++a) {
            ids[a] = gtype == 17 ? g[kHex20Perm[a]] : gtype == 11 ? g[kTet10Perm[a]] : g[a];
          }
          const std::span<const std::size_t> span(ids.data(), static_cast<std::size_t>(nn));
          if (dim == 3) {
            const ElementType et = gtype == 4    ? ElementType::Tet4
                                   : gtype == 5  ? ElementType::Hex8
                                   : gtype == 11 ? ElementType::Tet10
                                                 : ElementType::Hex20;
            mesh.add_element(et, span, region);
            for (int p : phys)
              sets[group_name(3, p)].insert(sets[group_name(3, p)].end(), span.begin(), span.end());
          } else {
            const FaceType ft = gtype == 2   ? FaceType::Tri3
                                : gtype == 3 ? FaceType::Quad4
                                : gtype == 9 ? FaceType::Tri6
                                             : FaceType::Quad8;
            for (int p : phys) {
              mesh.add_face_element(group_name(2, p), ft, span);
              sets[group_name(2, p)].insert(sets[group_name(2, p)].end(), span.begin(), span.end());
            }
          }
        }
      }
      expect_end(r, section);
    } else {
      // Unknown or unused section ($Periodic, $NodeData, ...): skip to its end.
      while (true) {
        r.next(("$End" + section).c_str());
        if (r.line().rfind("$End" + section, 0) == 0) break;
      }
    }
  }
  if (!have_format) throw Error(path + ": not a Gmsh file (no $MeshFormat section)");
  if (mesh.num_elements() == 0) {
    throw Error(path +
                ": no volume elements (tet4, hex8, tet10, hex20); mesh a volume and save it");
  }
  for (auto& [name, ids] : sets) mesh.add_node_set(name, ids);
  std::vector<std::size_t> all;
  for (const auto& e : mesh.elements())
    all.insert(all.end(), e.node_span().begin(), e.node_span().end());
  if (!mesh.has_node_set("all")) mesh.add_node_set("all", all);
  try {
    mesh.remove_unused_nodes();
    mesh.orient_faces_outward();
    mesh.validate();
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  return mesh;
}

}  // namespace partita::fem
