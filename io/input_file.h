// Opening a user's file and reporting what is wrong with it. Every reader goes
// through `read_input_file` (missing, directory, empty) and reports bad content
// with `input_error`, so all messages share one shape: "<path>:<where>: <what>".
#pragma once
#include <cstdint>
#include <string>

namespace jsa {

// Throws jsa::InputError("<path>:<where>: <what>"), or "<path>: <what>" if where is empty.
[[noreturn]] void input_error(const std::string& path, const std::string& where,
                              const std::string& what);

// "line 12" — the usual `where` for text formats.
std::string line_label(std::int64_t line);

// Rejects a missing path and a directory (before we look at the extension).
void check_regular_file(const std::string& path);

// The whole file as bytes. Rejects a missing path, a directory and an empty file.
std::string read_input_file(const std::string& path);

// Rejects text files that hold NUL bytes (a binary file with a text extension).
void reject_binary_bytes(const std::string& path, const std::string& bytes);

// Lower-cased extension with its dot (".obj"), or "" if the name has none.
std::string extension_of(const std::string& path);

}  // namespace jsa
