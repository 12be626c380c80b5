// BinaryWriter's recording and replay (a participant in another process writes its restart data
// into memory; the run's file must get the bytes and checksum table it would get in process),
// and BinaryReader::raw_until (the controller hands such a participant its part of the file).
#include <catch2/catch.hpp>

#include <sstream>

#include "partita/interface/binary_io.hpp"

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
