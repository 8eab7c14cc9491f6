// A pseudo-terminal pair in raw mode: a serial line inside one machine, so Modbus RTU can be
// tested without serial hardware (docs/modbus-transport.md); libmodbus and mbpoll open the far
// end like any tty.
#pragma once

#include <string>

namespace pathstream::hal {

/// Owns both ends of a pty. The caller reads and writes the near end (`fd()`, the master);
/// another program opens `peer_path()` (/dev/pts/N) as its serial port. The peer end is kept
/// open here as well, so the near end never sees EIO/hang-up while no program has the peer
/// open, and data written before the peer opens waits in its input queue.
/// Raw mode (cfmakeraw): no echo, no line editing, no CR/LF translation, 8-bit clean.
/// Linux host only. Move-only; closes both ends on destruction.
class PseudoTerminal {
public:
    /// Opens a new pair (posix_openpt). `nonblocking` sets O_NONBLOCK on the near end.
    /// Throws std::system_error when the system has no free pty.
    explicit PseudoTerminal(bool nonblocking = false);
    ~PseudoTerminal();
    PseudoTerminal(PseudoTerminal&& other) noexcept;
    PseudoTerminal& operator=(PseudoTerminal&& other) noexcept;
    PseudoTerminal(const PseudoTerminal&) = delete;
    PseudoTerminal& operator=(const PseudoTerminal&) = delete;

    /// The near end (master); owned by this object. -1 after a move.
    int fd() const noexcept { return master_; }
    /// The path another program opens, e.g. /dev/pts/7.
    const std::string& peer_path() const noexcept { return peer_path_; }

private:
    void close_all() noexcept;

    int master_ = -1;
    int peer_ = -1;  // held open: see the class comment
    std::string peer_path_;
};

}  // namespace pathstream::hal
