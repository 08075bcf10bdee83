// Writing a file so that it is either whole or not there: the one way refray writes any output (images, envelopes,
// statistics images, manifests, reports, JSON, job lists).
//
// The bytes go to a temporary file in the target's folder; every write, the flush to disk and the close are checked
// (an error names the file and the OS's reason, e.g. "no space left on device"), and only then is the temporary file
// renamed over the target. On any failure the target keeps its old contents (or stays absent) and the temporary
// file is removed; removeTemporaryFilesOnSignal() extends that to SIGINT, SIGTERM, SIGHUP and SIGQUIT.
#pragma once

#include <string>
#include <string_view>

namespace refray {

// Writes `bytes` as `path`, creating its folder; throws refray::Error naming `path` and the reason. A symbolic link
// at `path` is written through (its target is replaced); a directory, device, FIFO or socket at `path` is refused.
void writeFileAtomically(const std::string& path, std::string_view bytes);

// Checks, before any work, that `path` can become a regular file: no ancestor of it is a file (so its folder can
// exist) and `path` itself is not a directory, device, FIFO or socket. Throws refray::Error naming both.
void checkOutputPath(const std::string& path);

// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGQUIT that remove the temporary files being written and then
// end the process by the same signal (so its status still says which). SIGHUP and SIGQUIT stay ignored where they
// were (nohup); SIGINT and SIGTERM are handled even where a shell started refray with them ignored.
// Also ignores SIGXFSZ, so that a file-size limit fails the write ("file too large") instead of killing the process
// mid-file. Called once by the command line at start.
void removeTemporaryFilesOnSignal();

}  // namespace refray
