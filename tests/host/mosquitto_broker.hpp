// A real MQTT broker for tests: Debian's mosquitto on loopback, with its own configuration,
// port and (optionally) password file, stopped when the object goes.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace pathstream::test {

class MosquittoBroker {
public:
    /// `users`: name -> password; empty: anonymous clients are allowed.
    explicit MosquittoBroker(std::map<std::string, std::string> users = {}) {
        char dir_template[] = "/tmp/pathstream-mosquitto-XXXXXX";
        if (!mkdtemp(dir_template)) throw std::runtime_error("mkdtemp failed");
        dir_ = dir_template;
        // Started as root, mosquitto drops to its own user: it must be able to read here.
        std::filesystem::permissions(
            dir_, std::filesystem::perms::owner_all | std::filesystem::perms::group_read |
                      std::filesystem::perms::group_exec | std::filesystem::perms::others_read |
                      std::filesystem::perms::others_exec);
        if (!users.empty()) {
            for (const auto& [name, password] : users) {
                const std::string cmd =
                    "mosquitto_passwd -b " +
                    std::string(std::filesystem::exists(dir_ + "/passwd") ? "" : "-c ") + dir_ +
                    "/passwd " + name + " " + password + " > /dev/null 2>&1";
                if (std::system(cmd.c_str()) != 0)
                    throw std::runtime_error("mosquitto_passwd failed");
            }
        }
        // A free port can be taken between the probe and the broker's bind: try a few.
        for (int attempt = 0; attempt < 5 && pid_ <= 0; ++attempt) {
            port_ = free_port();
            std::ofstream(dir_ + "/mosquitto.conf")
                << "listener " << port_ << " 127.0.0.1\n"
                << "allow_anonymous " << (users.empty() ? "true" : "false") << "\n"
                << (users.empty() ? "" : "password_file " + dir_ + "/passwd\n")
                << "persistence false\nlog_dest stderr\n"
                << "max_queued_messages 100000\n";
            start();
        }
        if (pid_ <= 0) throw std::runtime_error("mosquitto did not start: see " + dir_);
    }
    ~MosquittoBroker() {
        stop();
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
    MosquittoBroker(const MosquittoBroker&) = delete;
    MosquittoBroker& operator=(const MosquittoBroker&) = delete;

    int port() const { return port_; }
    /// The broker's process (its CPU time is in /proc/PID/stat).
    pid_t pid() const { return pid_; }
    std::string url(const std::string& user = "", const std::string& password = "") const {
        std::string auth =
            user.empty() ? "" : user + (password.empty() ? "" : ":" + password) + "@";
        return "mqtt://" + auth + "127.0.0.1:" + std::to_string(port_);
    }
    void stop() {
        if (pid_ <= 0) return;
        kill(pid_, SIGTERM);
        int status = 0;
        waitpid(pid_, &status, 0);
        pid_ = -1;
    }

private:
    static int free_port() {
        const int fd = socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = 0;
        socklen_t len = sizeof a;
        bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
        getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
        close(fd);
        return ntohs(a.sin_port);
    }

    static bool accepts(int port) {
        const int fd = socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = htons(static_cast<std::uint16_t>(port));
        const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
        close(fd);
        return ok;
    }

    void start() {
        const std::string conf = dir_ + "/mosquitto.conf";
        std::vector<char*> argv{const_cast<char*>("/usr/sbin/mosquitto"), const_cast<char*>("-c"),
                                const_cast<char*>(conf.c_str()), nullptr};
        pid_t pid = 0;
        // Its log goes to a file we open, whoever it runs as.
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        const std::string log = dir_ + "/mosquitto.log";
        posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                         0644);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (rc != 0) return;
        // Ready when it accepts connections; gone (the port was taken) when it exits.
        for (int i = 0; i < 200; ++i) {
            int status = 0;
            if (waitpid(pid, &status, WNOHANG) == pid) return;
            if (accepts(port_)) {
                pid_ = pid;
                return;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
        }
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
    }

    std::string dir_;
    int port_ = 0;
    pid_t pid_ = -1;
};

}  // namespace pathstream::test
