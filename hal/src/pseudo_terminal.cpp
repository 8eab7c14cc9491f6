#include "pathstream/hal/pseudo_terminal.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <system_error>
#include <utility>

namespace pathstream::hal {
namespace {

[[noreturn]] void throw_errno(const char* what) {
    throw std::system_error(errno, std::generic_category(), what);
}

}  // namespace

PseudoTerminal::PseudoTerminal(bool nonblocking) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0) throw_errno("posix_openpt");
    try {
        if (grantpt(master_) != 0) throw_errno("grantpt");
        if (unlockpt(master_) != 0) throw_errno("unlockpt");
        char name[128];
        if (ptsname_r(master_, name, sizeof name) != 0) throw_errno("ptsname_r");
        peer_path_ = name;
        peer_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
        if (peer_ < 0) throw_errno("open pty peer");
        // The line discipline sits on the peer side: raw mode there makes the pair 8-bit
        // clean in both directions (no echo back to the master, no ^C, no CR/LF mapping).
        termios tio{};
        if (tcgetattr(peer_, &tio) != 0) throw_errno("tcgetattr");
        cfmakeraw(&tio);
        if (tcsetattr(peer_, TCSANOW, &tio) != 0) throw_errno("tcsetattr");
        if (nonblocking) {
            const int flags = fcntl(master_, F_GETFL);
            if (flags < 0 || fcntl(master_, F_SETFL, flags | O_NONBLOCK) != 0) throw_errno("fcntl");
        }
    } catch (...) {
        close_all();
        throw;
    }
}

PseudoTerminal::~PseudoTerminal() {
    close_all();
}

PseudoTerminal::PseudoTerminal(PseudoTerminal&& other) noexcept
    : master_(std::exchange(other.master_, -1)),
      peer_(std::exchange(other.peer_, -1)),
      peer_path_(std::move(other.peer_path_)) {}

PseudoTerminal& PseudoTerminal::operator=(PseudoTerminal&& other) noexcept {
    if (this != &other) {
        close_all();
        master_ = std::exchange(other.master_, -1);
        peer_ = std::exchange(other.peer_, -1);
        peer_path_ = std::move(other.peer_path_);
    }
    return *this;
}

void PseudoTerminal::close_all() noexcept {
    if (peer_ >= 0) ::close(peer_);
    if (master_ >= 0) ::close(master_);
    peer_ = master_ = -1;
}

}  // namespace pathstream::hal
