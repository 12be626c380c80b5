#include "partita/fem/gmsh_reader.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

// Counts and tags of a mesh that partita can hold: the solver numbers degrees of freedom (3 per
// node) and elements with 32-bit integers, so larger meshes are refused rather than wrapped.
constexpr long kMaxNodes = std::numeric_limits<int>::max() / 3;
constexpr long kMaxElements = std::numeric_limits<int>::max();
constexpr long kMaxTag = std::numeric_limits<int>::max();

// Line-oriented reader that knows where it is, for error messages "file:line: ...", and how many
// bytes remain (so that a count read from the file can be checked against what the file holds).
class LineReader {
 public:
  LineReader(std::istream& in, const std::string& source) : source_(source), in_(in) {
    const auto here = in_.tellg();
    if (here != std::streampos(-1) && in_.seekg(0, std::ios::end)) {
      const auto end = in_.tellg();
      in_.seekg(here);
      if (end != std::streampos(-1) && end >= here) size_ = static_cast<std::size_t>(end - here);
    }
    in_.clear();
  }
  // Next non-empty line; throws at end of file, saying what was expected.
  const std::string& next(const char* expected) {
    if (next_if_any()) return line_;
    throw Error(source_ + ":" + std::to_string(number_) + ": unexpected end of file; expected " +
                expected);
  }
  bool next_if_any() {
    while (std::getline(in_, line_)) {
      ++number_;
      consumed_ += line_.size() + 1;
      if (!line_.empty() && line_.back() == '\r') line_.pop_back();
      if (line_.find_first_not_of(" \t") != std::string::npos) return true;
    }
    return false;
  }
  const std::string& line() const { return line_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + ":" + std::to_string(number_) + ": " + what + " (line: '" +
                line_.substr(0, 80) + "')");
  }
  // The whitespace-separated fields of the current line, at least `min` of them.
  std::vector<std::string_view> fields(std::size_t min, const std::string& what) const {
    std::vector<std::string_view> v;
    std::size_t i = 0;
    while (true) {
      i = line_.find_first_not_of(" \t", i);
      if (i == std::string::npos) break;
      const std::size_t e = std::min(line_.find_first_of(" \t", i), line_.size());
      v.emplace_back(line_.data() + i, e - i);
      i = e;
    }
    if (v.size() < min) {
      fail("expected " + std::to_string(min) + " numbers in " + what + ", found " +
           std::to_string(v.size()));
    }
    return v;
  }
  // Parses the current line as numbers; at least `min` of them. Reals must be finite.
  template <class T>
  std::vector<T> numbers(std::size_t min, const std::string& what) const {
    std::vector<T> v;
    for (const std::string_view f : fields(min, what)) {
      T x{};
      const auto r = std::from_chars(f.data(), f.data() + f.size(), x);
      if (r.ec == std::errc::result_out_of_range)
        fail("number '" + std::string(f) + "' in " + what + " is out of range");
      if (r.ec != std::errc() || r.ptr != f.data() + f.size()) {
        fail("'" + std::string(f) + "' in " + what + " is not " +
             (std::is_integral_v<T> ? "an integer" : "a number"));
      }
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(x)) fail("'" + std::string(f) + "' in " + what + " is not finite");
      }
      v.push_back(x);
    }
    return v;
  }
  // A count read from the file: 0 <= n <= max, and n items of at least `bytes_each` bytes
  // must fit in what remains of the file.
  std::size_t count(long n, const std::string& what, long max, std::size_t bytes_each) const {
    if (n < 0) fail("negative " + what + " " + std::to_string(n) + "; allowed: 0 or more");
    if (n > max) {
      fail(what + " " + std::to_string(n) + " is too large; allowed: at most " +
           std::to_string(max));
    }
    const auto un = static_cast<std::size_t>(n);
    const std::size_t left = remaining();
    if (bytes_each > 0 && un > left / bytes_each) {
      fail(what + " " + std::to_string(n) + " cannot be right: the file ends too soon (" +
           std::to_string(n) + " items take at least " + std::to_string(bytes_each) +
           " bytes each, the rest of the file holds " + std::to_string(left) + ")");
    }
    return un;
  }
  // An integer field (tag, dimension, type) in [lo, hi].
  long in_range(long v, const std::string& what, long lo, long hi) const {
    if (v < lo || v > hi) {
      fail(what + " " + std::to_string(v) + " is out of range; allowed: " + std::to_string(lo) +
           " to " + std::to_string(hi));
    }
    return v;
  }
  // A whole number written as a real (the tags of $Entities lines) in [lo, hi].
  int whole(double v, const std::string& what, long lo, long hi) const {
    if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi)) || v != std::floor(v)) {
      char text[32];
      const auto end = std::to_chars(text, text + sizeof text, v).ptr;  // shortest exact form
      fail(what + " " + std::string(text, end) + " is not a whole number from " +
           std::to_string(lo) + " to " + std::to_string(hi));
    }
    return static_cast<int>(v);
  }

 private:
  std::size_t remaining() const { return consumed_ < size_ ? size_ - consumed_ : 0; }

  std::string source_;
  std::istream& in_;
  std::string line_;
  std::size_t number_ = 0;
  std::size_t consumed_ = 0;
  std::size_t size_ = std::numeric_limits<std::size_t>::max();  // unknown: no byte check
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
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the mesh file");
  return read_gmsh(in, path);
}

Mesh read_gmsh(std::istream& in, const std::string& source) {
  LineReader r(in, source);
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
  auto node_of = [&](long tag) {
    const auto it = tag < 1 ? node_index.end() : node_index.find(static_cast<std::size_t>(tag));
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
      // each line at least 'd t ""' and its line end
      const std::size_t n = r.count(r.numbers<long>(1, "the $PhysicalNames count")[0],
                                    "$PhysicalNames count", kMaxTag, 7);
      for (std::size_t i = 0; i < n; ++i) {
        r.next("a physical name line 'dim tag \"name\"'");
        const auto q0 = r.line().find('"'), q1 = r.line().rfind('"');
        if (q0 == std::string::npos || q1 <= q0) r.fail("expected 'dim tag \"name\"'");
        const auto fields = r.fields(2, "a physical name line 'dim tag \"name\"'");
        if (fields[0].data() + fields[0].size() > r.line().data() + q0 ||
            fields[1].data() + fields[1].size() > r.line().data() + q0)
          r.fail("expected 'dim tag \"name\"'");
        long dim = -1, tag = -1;
        for (auto [f, v] : {std::pair{fields[0], &dim}, std::pair{fields[1], &tag}}) {
          const auto res = std::from_chars(f.data(), f.data() + f.size(), *v);
          if (res.ec != std::errc() || res.ptr != f.data() + f.size())
            r.fail("'" + std::string(f) + "' in a physical name line is not an integer");
        }
        const int d = static_cast<int>(r.in_range(dim, "physical group dimension", 0, 3));
        const int t = static_cast<int>(r.in_range(tag, "physical tag", -kMaxTag, kMaxTag));
        physical_names[{d, t}] = r.line().substr(q0 + 1, q1 - q0 - 1);
      }
      expect_end(r, section);
    } else if (section == "Entities") {
      r.next("entity counts");
      const auto counts = r.numbers<long>(4, "$Entities counts (points curves surfaces volumes)");
      std::array<std::size_t, 4> n{};
      for (int dim = 0; dim < 4; ++dim) {
        static const char* kWhat[] = {"number of points", "number of curves", "number of surfaces",
                                      "number of volumes"};
        // a point line holds at least 5 numbers, the others at least 8: 2 bytes each
        n[dim] = r.count(counts[static_cast<std::size_t>(dim)],
                         std::string("$Entities ") + kWhat[dim], kMaxTag, dim == 0 ? 10 : 16);
      }
      for (int dim = 0; dim < 4; ++dim) {
        for (std::size_t i = 0; i < n[dim]; ++i) {
          r.next("an entity line");
          const auto v = r.numbers<double>(dim == 0 ? 5 : 8, "an entity line");
          const std::size_t np_at = dim == 0 ? 4 : 7;
          const int tag = r.whole(v[0], "entity tag", -kMaxTag, kMaxTag);
          const auto np = static_cast<std::size_t>(
              r.whole(v[np_at], "number of physical tags", 0, static_cast<long>(v.size())));
          if (np > v.size() - np_at - 1)
            r.fail("entity line lists fewer physical tags than announced (" + std::to_string(np) +
                   ")");
          std::vector<int> tags;
          for (std::size_t k = 0; k < np; ++k)
            tags.push_back(r.whole(v[np_at + 1 + k], "physical tag", -kMaxTag, kMaxTag));
          entity_physicals[{dim, tag}] = tags;
        }
      }
      expect_end(r, section);
    } else if (section == "Nodes") {
      r.next("'numEntityBlocks numNodes minNodeTag maxNodeTag'");
      const auto h = r.numbers<long>(4, "the $Nodes header");
      // a block header is at least "0 1 0 0\n"; a node at least "1\n0 0 0\n"
      const std::size_t blocks = r.count(h[0], "number of node blocks", kMaxNodes, 8);
      const std::size_t total = r.count(h[1], "number of nodes", kMaxNodes, 8);
      std::size_t read = 0;
      for (std::size_t b = 0; b < blocks; ++b) {
        r.next("a node block header 'entityDim entityTag parametric numNodesInBlock'");
        const auto bh = r.numbers<long>(4, "a node block header");
        r.in_range(bh[0], "entity dimension", 0, 3);
        r.in_range(bh[2], "parametric flag", 0, 1);
        if (bh[2] != 0)
          r.fail("parametric nodes are not supported; save without parametric coordinates");
        const std::size_t nb = r.count(bh[3], "number of nodes in a block", kMaxNodes, 8);
        if (nb > total - read) {
          r.fail("this block's " + std::to_string(nb) + " nodes exceed the " +
                 std::to_string(total) + " nodes announced in the $Nodes header");
        }
        read += nb;
        std::vector<std::size_t> tags;
        tags.reserve(nb);
        for (std::size_t k = 0; k < nb; ++k) {
          r.next("a node tag");
          const long tag = r.in_range(r.numbers<long>(1, "a node tag")[0], "node tag", 1,
                                      std::numeric_limits<long>::max());
          tags.push_back(static_cast<std::size_t>(tag));
        }
        for (std::size_t k = 0; k < nb; ++k) {
          r.next("node coordinates 'x y z'");
          const auto x = r.numbers<double>(3, "node coordinates");
          if (!node_index.emplace(tags[k], mesh.num_nodes()).second)
            r.fail("node tag " + std::to_string(tags[k]) + " appears twice in $Nodes");
          mesh.add_node(Vec3(x[0], x[1], x[2]));
        }
      }
      if (read != total) {
        r.fail("$Nodes announced " + std::to_string(total) + " nodes but its blocks hold " +
               std::to_string(read));
      }
      expect_end(r, section);
      have_nodes = true;
    } else if (section == "Elements") {
      if (!have_nodes) r.fail("$Elements before $Nodes");
      r.next("'numEntityBlocks numElements minElementTag maxElementTag'");
      const auto h = r.numbers<long>(4, "the $Elements header");
      // a block header is at least "0 1 15 0\n"; an element line at least "1 1\n"
      const std::size_t blocks = r.count(h[0], "number of element blocks", kMaxElements, 9);
      const std::size_t total = r.count(h[1], "number of elements", kMaxElements, 4);
      std::size_t read = 0;
      int default_region = -1;
      for (std::size_t b = 0; b < blocks; ++b) {
        r.next("an element block header 'entityDim entityTag elementType numElementsInBlock'");
        const auto bh = r.numbers<long>(4, "an element block header");
        const int dim = static_cast<int>(r.in_range(bh[0], "entity dimension", 0, 3));
        const int entity = static_cast<int>(r.in_range(bh[1], "entity tag", -kMaxTag, kMaxTag));
        const int gtype = static_cast<int>(r.in_range(bh[2], "element type", 1, kMaxTag));
        const auto it = kTypes.find(gtype);
        // each element line holds its tag and its nodes, at least 2 bytes each
        const int nn = it != kTypes.end() ? it->second.nodes : 1;
        const std::size_t nb = r.count(bh[3], "number of elements in a block", kMaxElements,
                                       2 * static_cast<std::size_t>(nn + 1));
        if (nb > total - read) {
          r.fail("this block's " + std::to_string(nb) + " elements exceed the " +
                 std::to_string(total) + " elements announced in the $Elements header");
        }
        read += nb;
        if (it == kTypes.end() || it->second.dim != dim) {
          if (dim <= 1) {  // unknown point/line types: skip the block
            for (std::size_t k = 0; k < nb; ++k) r.next("an element line");
            continue;
          }
          r.fail("element type " + std::to_string(gtype) + " in a " + std::to_string(dim) +
                 "D block is not supported; allowed: 4 (tet4), 5 (hex8), 11 (tet10), 17 (hex20) "
                 "and faces 2 (tri3), 3 (quad4), 9 (tri6), 16 (quad8); use "
                 "Mesh.SecondOrderIncomplete = 1");
        }
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
        for (std::size_t k = 0; k < nb; ++k) {
          r.next("an element line 'tag node ...'");
          const auto v = r.numbers<long>(1, "an element line (tag and its nodes)");
          if (v.size() != 1 + static_cast<std::size_t>(nn)) {
            r.fail("element of gmsh type " + std::to_string(gtype) + " needs " +
                   std::to_string(nn) + " nodes, found " + std::to_string(v.size() - 1));
          }
          r.in_range(v[0], "element tag", 1, std::numeric_limits<long>::max());
          if (dim <= 1) continue;
          std::array<std::size_t, kMaxElementNodes> g{};
          for (int a = 0; a < nn; ++a) g[a] = node_of(v[1 + a]);
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
      if (read != total) {
        r.fail("$Elements announced " + std::to_string(total) + " elements but its blocks hold " +
               std::to_string(read));
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
  if (!have_format) throw Error(source + ": not a Gmsh file (no $MeshFormat section)");
  if (mesh.num_elements() == 0) {
    throw Error(source +
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
    throw Error(source + ": " + e.what());
  }
  return mesh;
}

}  // namespace partita::fem
