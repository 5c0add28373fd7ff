// The docs against the tree: every file path the README and docs/*.md cite
// (`engine/tape.h`, `docs/cli.md`, `../README.md`, a bare `ops_linear.cpp`),
// every link anchor (`method.md#d1-...`), and every `jsatlas <subcommand>
// --flag` they show must exist: the file in the source tree, the anchor as a
// heading of that page, the subcommand in `jsatlas --help` and the flag in the
// subcommand's --help. A renamed file or flag then fails here instead of
// leaving a doc that lies. The first test shows the checker catching planted
// mistakes, so that a clean run of the second means something.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cctype>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test/cli_test_support.h"

namespace {

namespace fs = std::filesystem;
const fs::path kRoot = JSATLAS_SOURCE_DIR;

// GitHub's heading anchor: lower case, punctuation dropped, spaces to '-'.
std::string slug(const std::string& heading) {
  std::string s;
  for (char c : heading) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || c == '-' || c == '_')
      s += char(std::tolower(u));
    else if (c == ' ')
      s += '-';
  }
  return s;
}

std::set<std::string> anchors_of(const std::string& text) {
  std::set<std::string> a;
  static const std::regex heading(R"(^#{1,6} +(.*)$)", std::regex::multiline);
  for (std::sregex_iterator it(text.begin(), text.end(), heading), end; it != end; ++it)
    a.insert(slug((*it)[1]));
  return a;
}

// Every file name in the tree (outside build and hidden directories), for the
// bare names a doc cites without their folder.
const std::set<std::string>& file_names() {
  static const std::set<std::string> names = [] {
    std::set<std::string> n;
    for (auto it = fs::recursive_directory_iterator(kRoot);
         it != fs::recursive_directory_iterator(); ++it) {
      const std::string name = it->path().filename().string();
      if (it->is_directory() && (name.rfind("build", 0) == 0 || name[0] == '.'))
        it.disable_recursion_pending();
      else if (it->is_regular_file())
        n.insert(name);
    }
    return n;
  }();
  return names;
}

// The help text of `jsatlas` and of each subcommand, fetched once.
const std::string& help(const std::string& sub) {
  static std::map<std::string, std::string> cache;
  auto it = cache.find(sub);
  if (it == cache.end())
    it = cache.emplace(sub, cli_test::run((sub.empty() ? "" : sub + " ") + "--help").output).first;
  return it->second;
}

bool has_word(const std::string& text, const std::string& word) {
  const std::regex w("(^|[^A-Za-z0-9_-])" +
                     std::regex_replace(word, std::regex(R"([-])"), R"(\-)") +
                     "($|[^A-Za-z0-9_-])");
  return std::regex_search(text, w);
}

// Problems in one page's text; `dir` is the page's folder (links are relative to it).
std::vector<std::string> check_page(const std::string& name, const std::string& text,
                                    const fs::path& dir) {
  std::vector<std::string> problems;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool fenced = false;
  // (?!...): "view.html" is not a citation of "view.h".
  static const std::regex path_re(
      R"((\.\./|[A-Za-z0-9_])[A-Za-z0-9_./-]*\.(h|cpp|md)(?![A-Za-z0-9_])(#[A-Za-z0-9_-]+)?)");
  static const std::regex cmd_re(R"((^|[^A-Za-z0-9_:-])jsatlas ([a-z][a-z-]*))");
  static const std::regex flag_re(R"((^|[ \[(])(--[a-z0-9][a-z0-9-]*))");
  while (std::getline(lines, line)) {
    ++number;
    const std::string where = name + ":" + std::to_string(number) + ": ";
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    for (std::sregex_iterator it(line.begin(), line.end(), path_re), end; it != end; ++it) {
      std::string p = (*it).str();
      if (p.find("://") != std::string::npos) continue;
      const size_t start = size_t(it->position());
      // $HOME/..., URLs, and placeholders: test/<room>_<file>_test.cpp, OUT_DIR/report.md.
      if (start > 0 && std::string("$/<>").find(line[start - 1]) != std::string::npos) continue;
      if (std::regex_search(p, std::regex("^[A-Z][A-Z_]*/"))) continue;
      // A program the reader is asked to create: "// name.cpp: ..." in a code block.
      if (fenced && line.compare(0, 3, "// ") == 0 && start == 3 &&
          line.compare(start + p.size(), 1, ":") == 0)
        continue;
      std::string anchor;
      if (const size_t h = p.find('#'); h != std::string::npos)
        anchor = p.substr(h + 1), p = p.substr(0, h);
      fs::path found;
      if (p.find('/') == std::string::npos) {
        if (fs::exists(dir / p))
          found = dir / p;
        else if (!file_names().count(p))
          problems.push_back(where + "no file named " + p);
      } else if (fs::exists(kRoot / p)) {
        found = kRoot / p;
      } else if (fs::exists(dir / p)) {
        found = dir / p;
      } else if (p.rfind("include/jsatlas/", 0) != 0) {  // the install tree, not the source
        problems.push_back(where + "no such file " + p);
      }
      if (!anchor.empty() && !found.empty() &&
          !anchors_of(cli_test::read_text(found.string())).count(anchor))
        problems.push_back(where + "no heading #" + anchor + " in " + p);
    }
    // Same-page anchors: ](#anchor)
    static const std::regex self_re(R"(\]\(#([A-Za-z0-9_-]+)\))");
    for (std::sregex_iterator it(line.begin(), line.end(), self_re), end; it != end; ++it)
      if (!anchors_of(text).count((*it)[1]))
        problems.push_back(where + "no heading #" + (*it)[1].str() + " on this page");
    // jsatlas SUBCOMMAND [args]: the command runs to the end of its code span or line.
    for (std::sregex_iterator it(line.begin(), line.end(), cmd_re), end; it != end; ++it) {
      const std::string sub = (*it)[2];
      const size_t after = size_t(it->position(2) + it->length(2));
      const bool in_code = fenced || line.rfind("    ", 0) == 0 ||
                           std::count(line.begin(), line.begin() + it->position(2), '`') % 2 == 1;
      if (!has_word(help(""), sub)) {
        if (in_code) problems.push_back(where + "jsatlas has no subcommand " + sub);
        continue;  // prose: "jsatlas learns ..."
      }
      const size_t stop = std::min(line.find('`', after), line.size());
      const std::string args = line.substr(after, stop - after);
      for (std::sregex_iterator f(args.begin(), args.end(), flag_re), fend; f != fend; ++f)
        if (!has_word(help(sub), (*f)[2]))
          problems.push_back(where + "jsatlas " + sub + " has no flag " + (*f)[2].str());
    }
  }
  return problems;
}

std::vector<fs::path> pages() {
  std::vector<fs::path> p = {kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") p.push_back(e.path());
  std::sort(p.begin(), p.end());
  return p;
}

}  // namespace

TEST_CASE("doc checker: catches a wrong path, anchor, bare name, subcommand and flag",
          "[cli][docs]") {
  const std::string page =
      "See `engine/tape.h` and [the map](method.md#the-map) and `ops_linear.cpp`.\n"
      "Then `engine/tapes.h`, [x](method.md#no-such-heading), `ops_lineal.cpp`.\n"
      "    build/jsatlas fit a.obj -o out --iters 10 --no-such-flag\n"
      "Run `jsatlas evaluate DIR` and `jsatlas eval DIR --samples 5`.\n"
      "Placeholders pass: `test/<room>_<file>_test.cpp`, `OUT_DIR/report.md`.\n";
  const std::vector<std::string> p = check_page("planted.md", page, kRoot / "docs");
  std::string all;
  for (const auto& s : p) all += s + "\n";
  INFO(all);
  CHECK(p.size() == 5);
  CHECK(all.find("planted.md:2: no such file engine/tapes.h") != std::string::npos);
  CHECK(all.find("planted.md:2: no heading #no-such-heading in method.md") != std::string::npos);
  CHECK(all.find("planted.md:2: no file named ops_lineal.cpp") != std::string::npos);
  CHECK(all.find("planted.md:3: jsatlas fit has no flag --no-such-flag") != std::string::npos);
  CHECK(all.find("planted.md:4: jsatlas has no subcommand evaluate") != std::string::npos);
}

TEST_CASE("README.md and docs/*.md cite only files, anchors and flags that exist", "[cli][docs]") {
  REQUIRE(help("").find("fit") != std::string::npos);  // the binary runs
  std::vector<std::string> problems;
  for (const fs::path& page : pages()) {
    const auto p = check_page(fs::relative(page, kRoot).string(),
                              cli_test::read_text(page.string()), page.parent_path());
    problems.insert(problems.end(), p.begin(), p.end());
  }
  std::string all;
  for (const auto& s : problems) all += s + "\n";
  INFO(pages().size() << " pages; problems:\n" << all);
  CHECK(problems.empty());
}
