// Plot files on disk: SVGs through AtomicFile, PNGs from rsvg-convert run without a shell.
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "pathstream/host/plot.hpp"
#include "pathstream/machine/atomic_file.hpp"

extern char** environ;

namespace pathstream::host::plot {
namespace {

void write_text(const std::string& file, const std::string& text) {
    AtomicFile out(file);
    out.stream() << text;
    out.commit();
}

std::string join(const std::string& directory, const std::string& name) {
    if (directory.empty()) return name;
    return directory.back() == '/' ? directory + name : directory + "/" + name;
}

/// Reads all of `fd` into a string (until EOF or an error).
std::string drain(int fd) {
    std::string out;
    char buf[65536];
    for (;;) {
        const ssize_t n = read(fd, buf, sizeof buf);
        if (n > 0) {
            out.append(buf, static_cast<std::size_t>(n));
        } else if (n < 0 && errno == EINTR) {
            continue;
        } else {
            break;
        }
    }
    return out;
}

/// Closes the descriptors it holds on scope exit.
struct Fds {
    int fd[4] = {-1, -1, -1, -1};
    ~Fds() {
        for (int f : fd) {
            if (f >= 0) close(f);
        }
    }
    void close_one(int i) {
        if (fd[i] >= 0) close(fd[i]);
        fd[i] = -1;
    }
};

}  // namespace

std::optional<std::string> find_rsvg_convert() {
    const char* path = std::getenv("PATH");
    std::string dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= dirs.size()) {
        std::size_t end = dirs.find(':', start);
        if (end == std::string::npos) end = dirs.size();
        const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
        const std::string candidate = join(dir, "rsvg-convert");
        struct stat st {};
        if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
            access(candidate.c_str(), X_OK) == 0) {
            return candidate;
        }
        start = end + 1;
    }
    return std::nullopt;
}

void svg_to_png(const std::string& rsvg, const std::string& svg_file, const std::string& png_file) {
    // rsvg-convert writes the PNG to a pipe that feeds an AtomicFile, its messages to a
    // temporary file; argv goes to execve verbatim (no shell, no quoting issues).
    AtomicFile out(png_file);
    Fds fds;
    int pipe_fds[2];
    if (pipe2(pipe_fds, O_CLOEXEC) != 0)
        throw std::runtime_error(png_file + ": pipe: " + std::strerror(errno));
    fds.fd[0] = pipe_fds[0];
    fds.fd[1] = pipe_fds[1];
    FILE* err = std::tmpfile();
    if (err == nullptr) throw std::runtime_error(png_file + ": tmpfile: " + std::strerror(errno));
    const int err_fd = fileno(err);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err_fd, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    std::string a0 = rsvg, a1 = "--background-color=white", a2 = "--format=png", a3 = "--",
                a4 = svg_file;
    char* argv[] = {a0.data(), a1.data(), a2.data(), a3.data(), a4.data(), nullptr};
    pid_t pid = 0;
    const int spawn_error = posix_spawn(&pid, rsvg.c_str(), &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawn_error != 0) {
        std::fclose(err);
        throw std::runtime_error(png_file + ": cannot run " + rsvg + ": " +
                                 std::strerror(spawn_error));
    }
    fds.close_one(1);
    const std::string png = drain(pipe_fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    std::string message;
    std::rewind(err);
    char buf[512];
    std::size_t got = 0;
    while ((got = std::fread(buf, 1, sizeof buf, err)) > 0 && message.size() < 4096)
        message.append(buf, got);
    std::fclose(err);
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r'))
        message.pop_back();
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (!ok || png.size() < 8 || png.compare(1, 3, "PNG") != 0) {
        std::string why = WIFEXITED(status)
                              ? "exit status " + std::to_string(WEXITSTATUS(status))
                              : "killed by signal " + std::to_string(WTERMSIG(status));
        throw std::runtime_error(png_file + ": rsvg-convert failed on " + svg_file + " (" + why +
                                 ")" + (message.empty() ? "" : ": " + message));
    }
    out.stream().write(png.data(), static_cast<std::streamsize>(png.size()));
    out.commit();
}

WrittenPlots write_plots(const std::string& directory, const std::vector<BezierSegment>& path,
                         const TickSeries& executed, const TickSeries* plant,
                         const MachineProfile& profile, const Options& options) {
    if (executed.axes == 0)
        throw std::invalid_argument("path_svg: the executed series has no axes");
    VectorSegmentSource source(path);
    return write_plots(directory, source,
                       record_of(executed, plant, profile, options.half_window_ticks), profile,
                       options);
}

WrittenPlots write_plots(const std::string& directory, SegmentSource& path, const RunRecord& record,
                         const MachineProfile& profile, const Options& options) {
    WrittenPlots w;
    std::vector<std::string> names = {"path", "speed", "acceleration"};
    std::vector<std::string> svgs = {path_svg(path, record, profile, options),
                                     speed_svg(record, profile, options),
                                     acceleration_svg(record, profile, options)};
    // A machine with x, y and z: z against time too, where plunges and retracts show.
    if (record.xyz) {
        names.push_back("z");
        svgs.push_back(z_svg(record, profile, options));
    }
    if (record.corner) {
        names.push_back("corner");
        svgs.push_back(corner_svg(*record.corner, options));
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string file = join(directory, names[i] + ".svg");
        write_text(file, svgs[i]);
        w.files.push_back(file);
    }
    if (!options.png) return w;
    const std::optional<std::string> rsvg = find_rsvg_convert();
    if (!rsvg) {
        w.note =
            "PNG copies skipped: rsvg-convert not found on PATH (Debian: apt-get install "
            "librsvg2-bin, or run scripts/setup.sh)";
        return w;
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
        const std::string png = join(directory, names[i] + ".png");
        svg_to_png(*rsvg, w.files[i], png);
        w.files.push_back(png);
    }
    w.png = true;
    return w;
}

}  // namespace pathstream::host::plot
