#include "pathstream/machine/atomic_file.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>

namespace pathstream::host {
namespace {

// The temporary file an interrupt must not leave behind (a 1.4 GB `plan -o` once stayed).
// The handler only reads it: unlink and raise are async-signal-safe.
std::atomic<const char*> g_temp_path{nullptr};
constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};

extern "C" void remove_temp_and_die(int signal_number) {
    if (const char* path = g_temp_path.load()) ::unlink(path);
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
}

// Installs the handler where the signal would end the process; a command with its own
// handler (stream's Ctrl-C hold) keeps it.
bool guard_temp(const std::string& temp) {
    const char* expected = nullptr;
    if (!g_temp_path.compare_exchange_strong(expected, temp.c_str())) return false;
    for (const int s : kSignals) {
        struct sigaction current {};
        if (::sigaction(s, nullptr, &current) == 0 && current.sa_handler == SIG_DFL) {
            std::signal(s, remove_temp_and_die);
        }
    }
    return true;
}

void unguard_temp() {
    for (const int s : kSignals) {
        struct sigaction current {};
        if (::sigaction(s, nullptr, &current) == 0 && current.sa_handler == remove_temp_and_die) {
            std::signal(s, SIG_DFL);
        }
    }
    g_temp_path.store(nullptr);
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
    std::error_code ec;
    const auto status = std::filesystem::status(path_, ec);
    if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status) &&
        !std::filesystem::is_directory(status)) {
        // A device or a pipe (/dev/null, a FIFO): written in place. Renaming a file onto it
        // would replace the device node (as root, /dev/null became a regular file once).
        direct_ = true;
        out_.open(path_, std::ios::binary);
        if (!out_) {
            throw std::runtime_error(path_ + ": cannot open output: " + std::strerror(errno));
        }
        return;
    }
    temp_ = path_ + ".tmp-" + std::to_string(::getpid());
    guarded_ = guard_temp(temp_);
    out_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!out_) {
        const int err = errno;
        if (guarded_) unguard_temp();
        throw std::runtime_error(path_ + ": cannot create output file: " + std::strerror(err));
    }
}

AtomicFile::~AtomicFile() {
    if (direct_) return;
    if (!committed_) {
        out_.close();
        std::remove(temp_.c_str());
    }
    if (guarded_) unguard_temp();
}

void AtomicFile::commit() {
    out_.flush();
    out_.close();
    if (!out_) throw std::runtime_error(path_ + ": write failed (disk full?)");
    committed_ = direct_;
    if (direct_) return;
    if (std::rename(temp_.c_str(), path_.c_str()) != 0) {
        throw std::runtime_error(path_ +
                                 ": cannot rename output into place: " + std::strerror(errno));
    }
    committed_ = true;
}

void write_output(const std::string& output, const std::function<void(std::ostream&)>& write) {
    if (output.empty() || output == "-") {
        write(std::cout);
        std::cout.flush();
        if (!std::cout) throw std::runtime_error("standard output: write failed");
        return;
    }
    AtomicFile file(output);
    write(file.stream());
    file.commit();
}

}  // namespace pathstream::host
