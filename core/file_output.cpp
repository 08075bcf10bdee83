#include "core/file_output.h"

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/os_error.h"

namespace refray {

namespace fs = std::filesystem;

namespace {

// ---- Temporary files in flight, for the signal handler ----------------------------------------------------------
// Fixed slots of plain characters: the handler may only call async-signal-safe functions, so it can neither lock nor
// allocate. A slot is Free, being Filled by a writer, or Ready (its path may be unlinked).

enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };
constexpr size_t kSlots = 32;
constexpr size_t kPathBytes = 4096;

struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes];
};
std::array<Slot, kSlots> gSlots;

// The slot holding `path`, or -1 when every slot is taken or the path is too long (the file is still removed on
// every failure the process survives).
int registerTemporary(const std::string& path) {
    if (path.size() >= kPathBytes) return -1;
    for (size_t i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!gSlots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(gSlots[i].path, path.c_str(), path.size() + 1);
        gSlots[i].state.store(kReady);
        return int(i);
    }
    return -1;
}

void unregisterTemporary(int slot) {
    if (slot >= 0) gSlots[size_t(slot)].state.store(kFree);
}

extern "C" void removeTemporariesAndDie(int signal) {
    for (Slot& slot : gSlots)
        if (slot.state.load() == kReady) ::unlink(slot.path);
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

// ---- Paths ------------------------------------------------------------------------------------------------------

// What is at `path` when it is not a regular file, for a message ("a directory"); empty for a regular file.
std::string notRegularFile(const fs::file_status& status) {
    switch (status.type()) {
        case fs::file_type::regular: return {};
        case fs::file_type::directory: return "a directory";
        case fs::file_type::block:
        case fs::file_type::character: return "a device";
        case fs::file_type::fifo: return "a FIFO";
        case fs::file_type::socket: return "a socket";
        default: return "not a regular file";
    }
}

// A name for the temporary file beside `target`, unique in this process and, through the process id, among
// processes writing the same folder.
fs::path temporaryPathFor(const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    std::string name = target.filename().string();
    if (name.size() > 180) name.resize(180);  // stay within NAME_MAX with the suffix
    return target.parent_path() /
           ("." + name + ".refray-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".tmp");
}

// The test suite's fault injection: REFRAY_TEST_WRITE_DELAY_MS holds every file, written in full but not yet
// renamed, for that long, so that a test can deliver a signal while a write is in flight.
void testDelayBeforeRename() {
    const char* delay = std::getenv("REFRAY_TEST_WRITE_DELAY_MS");
    if (!delay || !*delay) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(std::strtoul(delay, nullptr, 10)));
}

}  // namespace

void checkOutputPath(const std::string& path) {
    REFRAY_CHECK(!path.empty(), "an output file name is empty");
    const fs::path p(path);
    // The nearest ancestor that exists must be a folder; a file there means the folder can never be created.
    for (fs::path a = p.parent_path(); !a.empty(); a = a.parent_path()) {
        std::error_code error;
        const fs::file_status status = fs::status(a, error);
        if (status.type() == fs::file_type::not_found || error.value() == ENOTDIR) {
            if (a == a.parent_path()) break;
            continue;
        }
        REFRAY_CHECK(!error, "cannot write '" << path << "': cannot inspect its folder '" << a.string()
                                               << "': " << osReason(error.value()));
        REFRAY_CHECK(fs::is_directory(status),
                     "cannot write '" << path << "': '" << a.string() << "' is a file, not a folder"
                                      << (a == p.parent_path() ? std::string()
                                                               : ", so the folder '" + p.parent_path().string() +
                                                                     "' cannot exist"));
        break;
    }
    std::error_code error;
    const fs::file_status status = fs::status(p, error);
    if (status.type() == fs::file_type::not_found || error.value() == ENOTDIR) return;
    REFRAY_CHECK(!error, "cannot write '" << path << "': " << osReason(error.value()));
    const std::string kind = notRegularFile(status);
    REFRAY_CHECK(kind.empty(), "cannot write '" << path << "': it is " << kind
                                                << ", not a regular file; give an output file name");
}

void writeFileAtomically(const std::string& path, std::string_view bytes) {
    checkOutputPath(path);
    // Through a symbolic link to the file it names: renaming over the link would replace the link itself.
    fs::path target(path);
    std::error_code error;
    if (fs::is_symlink(fs::symlink_status(target, error))) {
        target = fs::weakly_canonical(target, error);
        REFRAY_CHECK(!error, "cannot write '" << path << "': cannot resolve the symbolic link: "
                                               << osReason(error.value()));
        checkOutputPath(target.string());
    }
    const fs::path folder = target.parent_path();
    if (!folder.empty()) {
        fs::create_directories(folder, error);
        REFRAY_CHECK(!error, "cannot write '" << path << "': cannot create its folder '" << folder.string()
                                               << "': " << osReason(error.value()));
    }

    const fs::path temporary = temporaryPathFor(target);
    const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    REFRAY_CHECK(fd >= 0, "cannot write '" << path << "': cannot create a file in '"
                                           << (folder.empty() ? std::string(".") : folder.string())
                                           << "': " << osReason(errno));
    const int slot = registerTemporary(temporary.string());
    const auto fail = [&](const std::string& what, int code, bool open) {
        if (open) ::close(fd);
        ::unlink(temporary.c_str());
        unregisterTemporary(slot);
        std::error_code ignored;
        throw Error("cannot write '" + path + "': " + what + osReason(code) + "; " +
                    (fs::exists(target, ignored) ? "the file there is unchanged" : "nothing was written"));
    };

    // A file replaced keeps its permissions.
    struct stat old {};
    if (::stat(target.c_str(), &old) == 0) (void)::fchmod(fd, old.st_mode & 07777);
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("", n < 0 ? errno : EIO, true);
        done += size_t(n);
    }
    if (::fsync(fd) != 0) fail("flushing it to disk: ", errno, true);
    if (::close(fd) != 0) fail("closing it: ", errno, false);
    testDelayBeforeRename();
    if (::rename(temporary.c_str(), target.c_str()) != 0) fail("renaming the finished file into place: ", errno, false);
    unregisterTemporary(slot);
    // The rename itself reaches the disk with its folder's entry.
    const int dir = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
        (void)::fsync(dir);
        ::close(dir);
    }
}

void removeTemporaryFilesOnSignal() {
    for (const int signal : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
        // SIGHUP and SIGQUIT stay ignored where a parent ignored them (nohup). SIGINT and SIGTERM are always handled:
        // a non-interactive shell starts background commands with SIGINT ignored, and 'kill -INT' must still stop
        // refray without a partial file.
        struct sigaction old {};
        const bool keepIgnored = signal == SIGHUP || signal == SIGQUIT;
        if (keepIgnored && ::sigaction(signal, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        struct sigaction action {};
        action.sa_handler = removeTemporariesAndDie;
        sigemptyset(&action.sa_mask);
        ::sigaction(signal, &action, nullptr);
    }
    std::signal(SIGXFSZ, SIG_IGN);
}

}  // namespace refray
