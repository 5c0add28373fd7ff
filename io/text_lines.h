// Walking a text file line by line for the OFF, PLY-ascii and xyz readers: skips
// blank lines and '#' comments, splits on whitespace, and keeps the 1-based line
// number so that errors can point at it. Numbers parse with std::from_chars.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace jsa {

struct TextLine {
  std::int64_t number = 0;               // 1-based line number in the file
  std::vector<std::string_view> tokens;  // whitespace-separated, comment removed
};

class TextLines {
 public:
  // Reads `bytes` from `offset`; the line starting there is line `first_number`.
  explicit TextLines(const std::string& bytes, std::size_t offset = 0,
                     std::int64_t first_number = 1);
  // The next line with at least one token; false at the end of the text.
  bool next(TextLine& line);
  std::int64_t last_number() const { return number_ - 1; }

 private:
  const std::string& bytes_;
  std::size_t pos_;
  std::int64_t number_;
};

// Whole-token parses; false if the token is not entirely a number of that kind.
bool parse_number(std::string_view token, double& value);
bool parse_number(std::string_view token, std::int64_t& value);

}  // namespace jsa
