// Line and number scanning shared by the text shape formats.
#include "io/text_lines.h"

#include <cctype>
#include <charconv>

namespace jsa {

TextLines::TextLines(const std::string& bytes, std::size_t offset, std::int64_t first_number)
    : bytes_(bytes), pos_(offset), number_(first_number) {}

bool TextLines::next(TextLine& line) {
  while (pos_ < bytes_.size()) {
    std::size_t end = bytes_.find('\n', pos_);
    if (end == std::string::npos) end = bytes_.size();
    std::string_view text(bytes_.data() + pos_, end - pos_);
    pos_ = end + 1;
    line.number = number_++;
    line.tokens.clear();
    const auto hash = text.find('#');
    if (hash != std::string_view::npos) text = text.substr(0, hash);
    std::size_t i = 0;
    while (i < text.size()) {
      while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
      std::size_t j = i;
      while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      if (j > i) line.tokens.push_back(text.substr(i, j - i));
      i = j;
    }
    if (!line.tokens.empty()) return true;
  }
  return false;
}

namespace {

template <class T>
bool parse_whole(std::string_view token, T& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

}  // namespace

bool parse_number(std::string_view token, double& value) { return parse_whole(token, value); }
bool parse_number(std::string_view token, std::int64_t& value) { return parse_whole(token, value); }

}  // namespace jsa
