// The bytes of the messages between processes (MessageWriter, MessageReader: binary_io.hpp):
// BinaryWriter's layout, values back to the bit, buffers reused, damaged messages refused with
// the peer named.
#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"

using partita::MessageReader;
using partita::MessageWriter;

namespace {

Eigen::MatrixXd sample_matrix(Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = 1.0 / 3.0 * static_cast<double>(i + 7 * j) - 2.5;
  return m;
}

}  // namespace

TEST_CASE("MessageWriter: the bytes of BinaryWriter for the same values (no sections)",
          "[interface][binary_io][remote]") {
  const Eigen::MatrixXd m = sample_matrix(5, 3);
  const std::vector<int> list{3, -1, 4};
  std::string buffer;
  MessageWriter out(buffer);
  std::ostringstream stream;
  partita::BinaryWriter reference(stream);
  const auto both = [&](const auto& v) {
    out.write(v);
    reference.write(v);
  };
  both(std::uint32_t{2});
  both(-0.0);
  both(std::numeric_limits<double>::quiet_NaN());
  both(std::string("bottom_quadrature"));
  both(std::string());
  both(list);
  both(m);
  CHECK(buffer == stream.str());
}

TEST_CASE("MessageReader: every value back to the bit, matrices into their storage",
          "[interface][binary_io][remote]") {
  const std::string peer = "participant 'granules' (rank 1)";
  const Eigen::MatrixXd m = sample_matrix(441, 3);
  std::string buffer = "stale bytes of a longer earlier message, cleared by the caller";
  buffer.clear();
  MessageWriter out(buffer);
  out.write(std::int64_t{-42});
  out.write(std::string("displacement"));
  out.write(m);
  out.write(std::uint8_t{1});

  Eigen::MatrixXd into(441, 3);
  const double* storage = into.data();
  std::string text = "a text whose storage is reused";
  MessageReader r(buffer, peer);
  CHECK(r.get<std::int64_t>() == -42);
  r.read(text);
  CHECK(text == "displacement");
  r.read(into);
  CHECK(into.data() == storage);  // the same shape: no new storage
  CHECK(into == m);               // every value to the bit
  CHECK(r.get<std::uint8_t>() == 1);
  CHECK(r.remaining() == 0);
}

TEST_CASE("MessageReader: a truncated or damaged message is an error naming the peer",
          "[interface][binary_io][remote]") {
  const std::string peer = "participant 'fluid' (rank 1)";
  std::string buffer;
  MessageWriter out(buffer);
  out.write(sample_matrix(4, 3));
  SECTION("cut short") {
    const std::string cut = buffer.substr(0, buffer.size() - 8);
    MessageReader r(cut, peer);
    Eigen::MatrixXd m;
    CHECK_THROWS_WITH(r.read(m), Catch::Contains("participant 'fluid' (rank 1) sent a damaged "
                                                 "message") &&
                                     Catch::Contains("a matrix of 4 x 3"));
  }
  SECTION("a count far above what remains allocates nothing and says what it expected") {
    std::string bad;
    MessageWriter(bad).write(std::uint64_t{1} << 60);
    MessageReader r(bad, peer);
    std::string s;
    CHECK_THROWS_WITH(r.read(s), Catch::Contains("sent a damaged message: expected a text of") &&
                                     Catch::Contains("0 bytes remain"));
    CHECK(s.empty());
  }
  SECTION("a number past the end") {
    MessageReader r(std::string_view(buffer).substr(0, 3), peer);
    CHECK_THROWS_AS(r.get<std::int64_t>(), partita::Error);
  }
}
