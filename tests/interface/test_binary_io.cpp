// StateArchive (one serialise function writes and reads a state: the bytes of the plain writer
// calls, every field back, a mismatch named); BinaryWriter's recording and replay (a participant in another process writes its restart data
// into memory; the run's file must get the bytes and checksum table it would get in process),
// and BinaryReader::raw_until (the controller hands such a participant its part of the file).
#include <catch2/catch.hpp>

#include <sstream>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/state_archive.hpp"

namespace {

// What a solver writes: data before any section, two sections, a matrix.
void write_state(partita::BinaryWriter& w) {
  w.write(std::uint32_t{42});
  w.section("dem");
  w.write(std::string("particles"));
  Eigen::MatrixXd m(3, 2);
  m << 1, 2, 3, 4, 5, 6;
  w.write(m);
  w.section("walls");
  w.write(std::vector<double>{0.5, 1.5});
}

std::string run_file(bool replayed) {
  std::ostringstream file;
  partita::BinaryWriter out(file);
  out.write(std::string("header of the run"));
  out.section("participant granules");
  if (replayed) {
    std::ostringstream memory;
    partita::BinaryWriter w(memory);
    write_state(w);
    out.replay(w.recording(memory.str()));
  } else {
    write_state(out);
  }
  out.section("end");
  out.write(std::int64_t{7});
  out.finish();
  return file.str();
}

}  // namespace

TEST_CASE("binary io: a replayed recording gives the bytes and checksums of writing in place",
          "[interface][binary_io]") {
  const std::string direct = run_file(false);
  const std::string replayed = run_file(true);
  REQUIRE(replayed == direct);  // the same sections, markers and CRC-32 table, byte for byte
}

TEST_CASE("binary io: raw_until takes one part of a verified file and reads on after it",
          "[interface][binary_io]") {
  std::istringstream file(run_file(false));
  partita::BinaryReader in(file, "run.bin");
  in.verify_checksums();
  CHECK(in.get_string() == "header of the run");
  in.expect_section("participant granules");
  const std::string part = in.raw_until([](const std::string& name) { return name == "end"; });
  // the part reads back as the solver wrote it
  std::istringstream ps(part);
  partita::BinaryReader p(ps, "part");
  CHECK(p.get<std::uint32_t>() == 42);
  p.expect_section("dem");
  CHECK(p.get_string() == "particles");
  Eigen::MatrixXd m;
  p.read(m);
  CHECK(m(2, 1) == 6.0);
  p.expect_section("walls");
  std::vector<double> v;
  p.read(v);
  CHECK(v == std::vector<double>{0.5, 1.5});
  // and the run's reader goes on at the next part
  in.expect_section("end");
  CHECK(in.get<std::int64_t>() == 7);
}

namespace {

// A state with one field of each kind a restart file holds, serialised by one function.
struct Thing {
  double x = 0.0;
  bool flag = false;
  long count = 0;
  std::string name;
  std::vector<int> list;
  Eigen::MatrixXd m;
  void serialize(partita::StateArchive& ar) {
    ar.section("thing");
    ar.io(x);
    ar.io(flag);
    ar.io(count);
    ar.io(name);
    ar.io(list);
    ar.io(m);
    if (ar.reading() && m.rows() != count) ar.fail("as many rows as the count");
  }
};

}  // namespace

TEST_CASE("state archive: one serialise function writes the plain writer's bytes and reads "
          "every field back",
          "[interface][binary_io]") {
  Thing a;
  a.x = -2.5;
  a.flag = true;
  a.count = 2;
  a.name = "iqn-ils";
  a.list = {3, 1, 4};
  a.m.setConstant(2, 3, 0.125);
  std::ostringstream archived, plain;
  {
    partita::BinaryWriter w(archived);
    partita::StateArchive ar(w);
    a.serialize(ar);
  }
  {  // the same fields by the writer's own calls (a bool as one byte)
    partita::BinaryWriter w(plain);
    w.section("thing");
    w.write(a.x);
    w.write(std::uint8_t{1});
    w.write(a.count);
    w.write(a.name);
    w.write(a.list);
    w.write(a.m);
  }
  CHECK(archived.str() == plain.str());

  std::istringstream in(archived.str());
  partita::BinaryReader r(in, "thing.bin");
  partita::StateArchive ar(r);
  Thing b;
  b.serialize(ar);
  CHECK(b.x == a.x);
  CHECK(b.flag);
  CHECK(b.count == a.count);
  CHECK(b.name == a.name);
  CHECK(b.list == a.list);
  CHECK(b.m == a.m);

  SECTION("a value that does not fit is named with the source") {
    a.count = 5;  // but two rows
    std::ostringstream bad;
    partita::BinaryWriter w(bad);
    partita::StateArchive wa(w);
    a.serialize(wa);
    std::istringstream bin(bad.str());
    partita::BinaryReader br(bin, "bad.bin");
    partita::StateArchive ra(br);
    Thing c;
    CHECK_THROWS_WITH(c.serialize(ra), Catch::Contains("bad.bin") &&
                                           Catch::Contains("as many rows as the count"));
  }
  SECTION("another section is named") {
    std::ostringstream other;
    partita::BinaryWriter w(other);
    w.section("other");
    std::istringstream bin(other.str());
    partita::BinaryReader br(bin, "other.bin");
    partita::StateArchive ra(br);
    Thing c;
    CHECK_THROWS_WITH(c.serialize(ra), Catch::Contains("the section 'thing', found 'other'"));
  }
}
