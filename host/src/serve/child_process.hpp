// Another pathstream command run by the server (stream, sim, ctl): the same code a user runs
// at the terminal, its standard output read line by line.
#pragma once

#include <sys/types.h>

#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace pathstream::host::serve {

/// A child process with its standard input on /dev/null and its standard output and error
/// on pipes, in a process group of its own (a Ctrl-C at the server's terminal is not its).
/// Owns the process: the destructor kills one still running and reaps it.
class ChildProcess {
public:
    /// Starts `argv[0]` (a path, not searched) in directory `cwd`. Throws std::system_error
    /// when it cannot be started.
    ChildProcess(const std::vector<std::string>& argv, const std::string& cwd);
    ~ChildProcess();
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    /// Reads until the child closes both pipes, calling `on_line` for every standard output
    /// line (without its newline) and keeping the last 16 KiB of standard error in
    /// `error_text`; then reaps it. Returns its exit status (128 + N when signal N ended it).
    /// Call once, from one thread. `abandon` (optional), asked every 100 ms, kills the child's
    /// process group when it returns true (the exit status is then 128 + SIGKILL).
    int wait(const std::function<void(const std::string&)>& on_line, std::string& error_text,
             const std::function<bool()>& abandon = {});

    /// Sends `signal` unless the child was reaped already. Any thread.
    void signal(int signal);

private:
    pid_t pid_ = -1;
    int out_ = -1, err_ = -1;
    std::mutex mutex_;  ///< guards reaped_ against a signal to a recycled pid
    bool reaped_ = false;
    int status_ = 0;
};

/// What a short command printed and how it ended.
struct ChildOutput {
    int exit_code = 0;
    std::string out;
    std::string err;
};

/// Runs `argv` to its end (see ChildProcess), collecting its output; `abandon` as in wait().
ChildOutput run_child(const std::vector<std::string>& argv, const std::string& cwd,
                      const std::function<bool()>& abandon = {});

/// The last `count` lines of a command's output that say something (a progress bar's last
/// state after its carriage returns): its error message. Linear in the text.
std::string last_lines(const std::string& text, std::size_t count);

/// The path of the running executable (/proc/self/exe), to start its other commands.
std::string self_executable();

}  // namespace pathstream::host::serve
