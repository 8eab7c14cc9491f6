// Output files appear whole or not at all: after an error, and after an interrupt that ends
// the process while the file is being written.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "pathstream/machine/atomic_file.hpp"

namespace fs = std::filesystem;
using pathstream::host::AtomicFile;
using pathstream::host::write_output;

namespace {

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() /
                         ("pathstream-atomic-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::size_t files_in(const fs::path& dir) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
    return n;
}

}  // namespace

TEST_CASE("an output file appears whole on commit, and not at all after an exception",
          "[host][atomic]") {
    const fs::path dir = fresh_dir("commit");
    const std::string path = (dir / "out.csv").string();
    write_output(path, [](std::ostream& out) { out << "tick,x\n0,1\n"; });
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(text == "tick,x\n0,1\n");
    CHECK(files_in(dir) == 1);
    const std::string other = (dir / "other.csv").string();
    CHECK_THROWS_AS(write_output(other,
                                 [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("planning failed");
                                 }),
                    std::runtime_error);
    CHECK_FALSE(fs::exists(other));
    CHECK(files_in(dir) == 1);
    fs::remove_all(dir);
}

TEST_CASE("an interrupt while an output file is written leaves no temporary file",
          "[host][atomic]") {
    for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
        INFO("signal " << signal_number);
        const fs::path dir = fresh_dir("signal" + std::to_string(signal_number));
        const std::string path = (dir / "big.csv").string();
        const pid_t child = ::fork();
        REQUIRE(child >= 0);
        if (child == 0) {
            std::signal(signal_number, SIG_DFL);
            AtomicFile file(path);
            file.stream() << "tick,x\n";
            file.stream().flush();
            std::raise(signal_number);  // as if the operator pressed Ctrl-C here
            std::_Exit(3);              // not reached: the signal ends the process
        }
        int status = 0;
        REQUIRE(::waitpid(child, &status, 0) == child);
        CHECK(WIFSIGNALED(status));
        CHECK(WTERMSIG(status) == signal_number);  // ended as the signal would have
        CHECK(files_in(dir) == 0);                 // neither big.csv nor big.csv.tmp-PID
        fs::remove_all(dir);
    }
}

TEST_CASE("a command's own interrupt handler is kept while a file is written", "[host][atomic]") {
    const fs::path dir = fresh_dir("handler");
    static volatile std::sig_atomic_t seen = 0;
    const auto previous = std::signal(SIGINT, [](int) { seen = 1; });
    {
        AtomicFile file((dir / "j.json").string());
        std::raise(SIGINT);
        CHECK(seen == 1);  // the command's handler ran: it decides (stream holds the job)
        file.commit();
    }
    CHECK(fs::exists(dir / "j.json"));
    std::signal(SIGINT, previous);
    fs::remove_all(dir);
}

TEST_CASE("an output to a FIFO is written in place, the FIFO stays one", "[host][atomic]") {
    // Renaming a finished file onto a device or a pipe would replace it: run as root,
    // `plan -o /dev/null` once turned /dev/null into a regular file.
    const fs::path dir = fresh_dir("fifo");
    const std::string fifo = (dir / "rows").string();
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    const pid_t reader = fork();
    REQUIRE(reader >= 0);
    if (reader == 0) {
        std::ifstream in(fifo);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        _exit(text == "tick,x\n0,1\n" ? 0 : 1);
    }
    write_output(fifo, [](std::ostream& out) { out << "tick,x\n0,1\n"; });
    int status = 0;
    REQUIRE(waitpid(reader, &status, 0) == reader);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
    CHECK(fs::is_fifo(fifo));
    CHECK(files_in(dir) == 1);
    fs::remove_all(dir);
}
