#include "child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <system_error>

extern char** environ;

namespace pathstream::host::serve {
namespace {

constexpr std::size_t kErrorTail = 16 * 1024;

void close_fd(int& fd) {
    if (fd >= 0) ::close(fd);
    fd = -1;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::string& cwd) {
    int out[2], err[2];
    if (::pipe2(out, O_CLOEXEC) != 0)
        throw std::system_error(errno, std::generic_category(), "pipe");
    if (::pipe2(err, O_CLOEXEC) != 0) {
        ::close(out[0]);
        ::close(out[1]);
        throw std::system_error(errno, std::generic_category(), "pipe");
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_adddup2(&actions, err[1], 2);
    posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(
        &attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    posix_spawnattr_setpgroup(&attributes, 0);
    sigset_t defaults, none;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigaddset(&defaults, SIGPIPE);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    sigemptyset(&none);
    posix_spawnattr_setsigmask(&attributes, &none);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const int r =
        ::posix_spawn(&pid_, argv.at(0).c_str(), &actions, &attributes, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    ::close(out[1]);
    ::close(err[1]);
    out_ = out[0];
    err_ = err[0];
    if (r != 0) {
        close_fd(out_);
        close_fd(err_);
        reaped_ = true;
        throw std::system_error(r, std::generic_category(), "cannot start " + argv.at(0));
    }
}

ChildProcess::~ChildProcess() {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (!reaped_) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, &status_, 0);
            reaped_ = true;
        }
    }
    close_fd(out_);
    close_fd(err_);
}

int ChildProcess::wait(const std::function<void(const std::string&)>& on_line,
                       std::string& error_text, const std::function<bool()>& abandon) {
    std::string line;
    char buffer[8192];
    bool killed = false;
    while (out_ >= 0 || err_ >= 0) {
        if (abandon && !killed && abandon()) {
            killed = true;
            const std::lock_guard<std::mutex> lock(mutex_);
            if (!reaped_) ::kill(-pid_, SIGKILL);  // its own process group (POSIX_SPAWN_SETPGROUP)
        }
        pollfd fds[2] = {{out_, POLLIN, 0}, {err_, POLLIN, 0}};
        const int ready = ::poll(fds, 2, abandon && !killed ? 100 : -1);
        if (ready == 0) continue;
        if (ready < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (int i = 0; i < 2; ++i) {
            int& fd = i == 0 ? out_ : err_;
            if (fd < 0 || (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
            const ssize_t n = ::read(fd, buffer, sizeof buffer);
            if (n <= 0) {
                if (n < 0 && errno == EINTR) continue;
                close_fd(fd);
                continue;
            }
            if (i == 1) {
                error_text.append(buffer, static_cast<std::size_t>(n));
                if (error_text.size() > kErrorTail)
                    error_text.erase(0, error_text.size() - kErrorTail);
                continue;
            }
            for (ssize_t k = 0; k < n; ++k) {
                if (buffer[k] == '\n') {
                    on_line(line);
                    line.clear();
                } else {
                    line += buffer[k];
                }
            }
        }
    }
    if (!line.empty()) on_line(line);
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!reaped_) {
        while (::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
        }
        reaped_ = true;
    }
    if (WIFEXITED(status_)) return WEXITSTATUS(status_);
    if (WIFSIGNALED(status_)) return 128 + WTERMSIG(status_);
    return 255;
}

void ChildProcess::signal(int signal) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!reaped_) ::kill(pid_, signal);
}

ChildOutput run_child(const std::vector<std::string>& argv, const std::string& cwd,
                      const std::function<bool()>& abandon) {
    ChildProcess child(argv, cwd);
    ChildOutput r;
    r.exit_code =
        child.wait([&](const std::string& line) { r.out += line + '\n'; }, r.err, abandon);
    return r;
}

std::string self_executable() {
    return std::filesystem::read_symlink("/proc/self/exe").string();
}

std::string last_lines(const std::string& text, std::size_t count) {
    std::vector<std::string> lines;
    std::size_t at = 0;
    while (at < text.size()) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        std::string line = text.substr(at, end - at);
        // A progress bar redraws with carriage returns: its last state is what was seen.
        if (const std::size_t cr = line.rfind('\r'); cr != std::string::npos)
            line = line.substr(cr + 1);
        if (!line.empty()) lines.push_back(line);
        at = end + 1;
    }
    std::string out;
    for (std::size_t i = lines.size() > count ? lines.size() - count : 0; i < lines.size(); ++i) {
        out += (out.empty() ? "" : "\n") + lines[i];
    }
    return out;
}

}  // namespace pathstream::host::serve
