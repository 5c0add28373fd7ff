// Writing a file so that readers only ever see the old version or the complete
// new one: write to a temporary file in the same directory, flush, fsync, then
// rename over the target. If the writer throws, the temporary is removed and the
// old file is untouched. Every jsatlas output (meshes, checkpoints) goes through here.
#pragma once
#include <functional>
#include <ostream>
#include <string>

namespace jsa {

// Calls `write` on a stream to a temporary next to `path`, then atomically
// replaces `path`. Throws InputError if the directory is missing or not
// writable, or if writing fails; rethrows whatever `write` throws.
void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace jsa
