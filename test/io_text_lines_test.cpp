// Tests for io/text_lines: comment and blank-line skipping, line numbers, number parsing.
#include <catch2/catch.hpp>

#include "io/text_lines.h"

TEST_CASE("TextLines skips blanks and comments and keeps line numbers", "[io][text_lines]") {
  const std::string text = "# header\n\n  1 2.5  three # note\r\n\t\n-4\n";
  jsa::TextLines lines(text);
  jsa::TextLine line;
  REQUIRE(lines.next(line));
  CHECK(line.number == 3);
  REQUIRE(line.tokens.size() == 3);
  CHECK(line.tokens[2] == "three");
  REQUIRE(lines.next(line));
  CHECK(line.number == 5);
  CHECK(line.tokens[0] == "-4");
  CHECK_FALSE(lines.next(line));
}

TEST_CASE("TextLines starts at an offset with a given line number", "[io][text_lines]") {
  const std::string text = "skip me\nkeep\n";
  jsa::TextLines lines(text, 8, 2);
  jsa::TextLine line;
  REQUIRE(lines.next(line));
  CHECK(line.number == 2);
  CHECK(line.tokens[0] == "keep");
}

TEST_CASE("parse_number accepts whole numbers only", "[io][text_lines]") {
  double d = 0;
  std::int64_t i = 0;
  CHECK(jsa::parse_number("1e-3", d));
  CHECK(d == Approx(1e-3));
  CHECK(jsa::parse_number("+2.5", d));
  CHECK(d == 2.5);
  CHECK_FALSE(jsa::parse_number("1.5x", d));
  CHECK_FALSE(jsa::parse_number("", d));
  CHECK(jsa::parse_number("-7", i));
  CHECK(i == -7);
  CHECK_FALSE(jsa::parse_number("7.0", i));
}
