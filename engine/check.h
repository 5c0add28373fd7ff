// Two kinds of failure, two kinds of error.
//  - JSA_CHECK(cond, msg): a programmer error (a broken invariant). Throws
//    jsa::InternalError carrying file:line, so a bug report points at the code.
//  - jsa::InputError: the user's input is bad (file, line or field, what is
//    wrong). Every main catches both at the top, prints one line, exits non-zero.
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>

namespace jsa {

struct InternalError : std::logic_error {
  using std::logic_error::logic_error;
};

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] inline void fail_check(const char* file, int line, const std::string& what) {
  std::ostringstream s;
  s << "internal error at " << file << ":" << line << ": " << what;
  throw InternalError(s.str());
}

}  // namespace jsa

#define JSA_CHECK(cond, msg)                                          \
  do {                                                                \
    if (!(cond)) {                                                    \
      std::ostringstream jsa_check_stream_;                           \
      jsa_check_stream_ << #cond << " failed: " << msg;               \
      ::jsa::fail_check(__FILE__, __LINE__, jsa_check_stream_.str()); \
    }                                                                 \
  } while (0)
