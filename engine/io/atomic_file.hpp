// Files written whole or not at all: a temporary file beside the target, then renamed into place.
// Used by the run, the frames and the CLI's and editor's scene files.
#pragma once

#include <functional>
#include <string>

namespace furrow {

// Atomic output: `write` fills a temporary file beside `path` (same directory, so the rename
// is atomic), which then replaces `path`; on any failure the temporary file is removed and
// std::runtime_error naming `path` is thrown. Readers never see a half-written file.
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp_path)>& write);
void write_file_atomic(const std::string& path, const std::string& bytes);
// Writes `text` to `path` through a temporary file in the same directory; an existing file is
// replaced only with `replace` (and then atomically), otherwise it is never touched and the error
// reads "PATH: exists; REPLACE_HINT".
void write_text_atomically(const std::string& path, const std::string& text, bool replace,
                           const std::string& replace_hint);

}  // namespace furrow
