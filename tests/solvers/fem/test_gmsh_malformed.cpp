// Gmsh import of malformed files: every count and tag read from the file is checked (sign, range,
// counts against the bytes that remain), so a short malformed file is a clear error naming the
// file, the line, what was found and what is allowed, never a crash or a silent wrap-around.
#include <catch2/catch.hpp>
#include <sstream>
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/gmsh_reader.hpp"

using namespace partita::fem;

namespace {
const std::string kHeader = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
// one Tet4 with nodes 1..4
const std::string kNodes =
    "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
const std::string kTet = "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";

Mesh read(const std::string& text) {
  std::istringstream in(text);
  return read_gmsh(in, "bad.msh");
}
}  // namespace

TEST_CASE("fem gmsh: the stream reader reads what the file reader reads", "[fem][gmsh]") {
  const Mesh m = read(kHeader + kNodes + kTet);
  CHECK(m.num_elements() == 1);
  CHECK(m.num_nodes() == 4);
}

TEST_CASE("fem gmsh: negative counts are errors, not wrapped sizes", "[fem][gmsh]") {
  // The input that crashed the reader (SIGSEGV): a negative number of physical tags.
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n1 0 0 0\n1 0 0 0 -5\n$EndEntities\n"),
                    Catch::Contains("bad.msh:6:") &&
                        Catch::Contains("number of physical tags -5 is not a whole number from 0"));
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n1 -2 0 0\n1 0 0 0 0\n$EndEntities\n"),
                    Catch::Contains("bad.msh:5:") &&
                        Catch::Contains("negative $Entities number of curves -2") &&
                        Catch::Contains("allowed: 0 or more"));
  CHECK_THROWS_WITH(read(kHeader + "$PhysicalNames\n-1\n$EndPhysicalNames\n"),
                    Catch::Contains("bad.msh:5:") && Catch::Contains("negative"));
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n-1 4 1 4\n$EndNodes\n"),
                    Catch::Contains("negative number of node blocks -1"));
  CHECK_THROWS_WITH(
      read(kHeader + "$Nodes\n1 0 1 4\n3 1 0 -4\n$EndNodes\n"),
      Catch::Contains("bad.msh:6:") && Catch::Contains("negative number of nodes in a block -4"));
  CHECK_THROWS_WITH(read(kHeader + kNodes + "$Elements\n1 -1 1 1\n$EndElements\n"),
                    Catch::Contains("negative number of elements -1"));
}

TEST_CASE("fem gmsh: huge counts are refused before anything is allocated", "[fem][gmsh]") {
  // Above 2^32: a 32-bit count would wrap to 1.
  CHECK_THROWS_WITH(
      read(kHeader + "$Nodes\n1 4294967297 1 4294967297\n0 1 0 4294967297\n1\n0 0 0\n$EndNodes\n"),
      Catch::Contains("bad.msh:5:") && Catch::Contains("number of nodes 4294967297 is too large") &&
          Catch::Contains("at most 715827882"));
  // Above 2^31 elements.
  CHECK_THROWS_WITH(
      read(kHeader + kNodes + "$Elements\n1 2147483648 1 2147483648\n3 1 4 1\n1 1 2 3 4\n"),
      Catch::Contains("number of elements 2147483648 is too large") &&
          Catch::Contains("at most 2147483647"));
  // Within the limits, but more than the rest of the file can hold.
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 1000000 1 1000000\n3 1 0 1000000\n1\n0 0 0\n"),
                    Catch::Contains("bad.msh:5:") &&
                        Catch::Contains("number of nodes 1000000 cannot be right") &&
                        Catch::Contains("bytes"));
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n0 0 0 100000\n$EndEntities\n"),
                    Catch::Contains("number of volumes 100000 cannot be right"));
  // A count beyond what a long holds.
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 99999999999999999999 1 4\n"),
                    Catch::Contains("bad.msh:5:") && Catch::Contains("out of range"));
  // Blocks holding more than the header announced.
  CHECK_THROWS_WITH(
      read(kHeader +
           "$Nodes\n1 1 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"),
      Catch::Contains("bad.msh:6:") && Catch::Contains("exceed the 1 nodes"));
}

TEST_CASE("fem gmsh: tags out of range are errors, not casts", "[fem][gmsh]") {
  // Tags of $Entities lines are written as reals: a huge or fractional one is not an int.
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n1 0 0 0\n1 0 0 0 1 1e300\n$EndEntities\n"),
                    Catch::Contains("bad.msh:6:") &&
                        Catch::Contains("physical tag 1e+300 is not a whole number"));
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n1 0 0 0\n2.5 0 0 0 0\n$EndEntities\n"),
                    Catch::Contains("entity tag 2.5 is not a whole number"));
  CHECK_THROWS_WITH(read(kHeader + "$Entities\n1 0 0 0\n1 0 0 0 1 nan\n$EndEntities\n"),
                    Catch::Contains("is not finite"));
  CHECK_THROWS_WITH(read(kHeader + "$PhysicalNames\n1\n3 99999999999 \"x\"\n$EndPhysicalNames\n"),
                    Catch::Contains("bad.msh:6:") && Catch::Contains("physical tag 99999999999"));
  CHECK_THROWS_WITH(read(kHeader + kNodes + "$Elements\n1 1 1 1\n3 1 4294967300 1\n1 1 2 3 4\n"),
                    Catch::Contains("element type 4294967300 is out of range"));
  CHECK_THROWS_WITH(read(kHeader + kNodes + "$Elements\n1 1 1 1\n7 1 4 1\n1 1 2 3 4\n"),
                    Catch::Contains("entity dimension 7 is out of range; allowed: 0 to 3"));
  CHECK_THROWS_WITH(read(kHeader + kNodes + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 -4\n"),
                    Catch::Contains("bad.msh:19:") && Catch::Contains("node -4"));
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 1 1 1\n3 1 0 1\n-1\n0 0 0\n$EndNodes\n"),
                    Catch::Contains("node tag -1 is out of range"));
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 2 1 2\n3 1 0 2\n1\n1\n0 0 0\n1 0 0\n$EndNodes\n"),
                    Catch::Contains("bad.msh:10:") && Catch::Contains("node tag 1 appears twice"));
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 1e999 0\n$EndNodes\n"),
                    Catch::Contains("bad.msh:8:") && Catch::Contains("out of range"));
  CHECK_THROWS_WITH(read(kHeader + "$Nodes\n1 1 1 1\n3 1 2 1\n$EndNodes\n"),
                    Catch::Contains("parametric flag 2 is out of range"));
}
