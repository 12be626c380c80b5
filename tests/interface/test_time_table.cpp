// TimeTable: linear between rows, held outside, strictly increasing times.

#include <catch2/catch.hpp>

#include "partita/interface/time_table.hpp"

using partita::TimeTable;

TEST_CASE("time table: ramp, hold, release", "[interface][time-table]") {
  const TimeTable t({{0.0, 0.0}, {1.0, 2.0}, {3.0, 2.0}, {4.0, -1.0}});
  CHECK(t(-1.0) == 0.0);          // held before the first row
  CHECK(t(0.25) == Approx(0.5));  // f0 + (t - t0)/(t1 - t0) (f1 - f0)
  CHECK(t(1.0) == 2.0);
  CHECK(t(2.0) == 2.0);
  CHECK(t(3.5) == Approx(0.5));
  CHECK(t(10.0) == -1.0);  // held after the last row
  CHECK(TimeTable()(5.0) == 1.0);
}

TEST_CASE("time table: from YAML, with units and errors that name the row",
          "[interface][time-table]") {
  using partita::config::Node;
  const Node n = Node::load_string("table: [[0, 0], [10 ms, 1], [20 ms, 0.5]]", "t.yaml");
  const TimeTable t = TimeTable::from_node(n["table"]);
  CHECK(t(0.005) == Approx(0.5));
  CHECK(t(0.015) == Approx(0.75));
  const Node bad = Node::load_string("table: [[0, 0], [2, 1], [1, 0]]", "bad.yaml");
  CHECK_THROWS_WITH(TimeTable::from_node(bad["table"]),
                    Catch::Contains("bad.yaml") && Catch::Contains("increase strictly"));
  const Node row = Node::load_string("table: [[0, 0], [1]]", "row.yaml");
  CHECK_THROWS_WITH(TimeTable::from_node(row["table"]), Catch::Contains("[time, factor]"));
  const Node empty = Node::load_string("table: []", "e.yaml");
  CHECK_THROWS_AS(TimeTable::from_node(empty["table"]), partita::Error);
}
