#!/usr/bin/python3
"""Run test programs inside Debian's real kernel under qemu-system-x86_64 (docs/vm.md).

Builds an initramfs (busybox-static, the kernel modules for SocketCAN/vcan, configfs and the
out-of-tree gpio-sim + irq_sim, can-utils and gpiod tools, the given programs with their shared
libraries and data files, /init from init.sh), boots it with the kernel that scripts/setup_vm.sh
unpacked, streams and saves the console, and exits with the test script's exit status.

  run_in_vm.py --work DIR --script test.sh [--program EXE]... [--data FILE]... [--gpio-sim]

Exit status: the test script's status inside the VM (200: the VM's own setup failed), or
  124  the VM did not print a result within --timeout seconds
  125  the VM stopped without printing a result, or the harness itself failed
With --expect-rc N: 0 when the script's status was N, 1 otherwise.

Accelerator (--accel, default auto): KVM is used only when a short probe boot under it
prints the kernel's first line; otherwise (no /dev/kvm, or a /dev/kvm that cannot run the
guest) the harness says so in one line and uses TCG. The verdict is cached in --base-cache,
so a suite pays for the probe once. PATHSTREAM_VM_KVM_ACCEL replaces the -accel option the
probe tries (default "kvm"); a value qemu cannot start exercises the fallback.
Uses only the Python standard library; run it with Debian's /usr/bin/python3.
"""

from __future__ import annotations

import argparse
import ctypes
import fcntl
import hashlib
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
RESULT_RE = re.compile(r"PATHSTREAM-VM-RESULT rc=(\d+)")
# Bump when the initramfs layout changes: every cached archive is rebuilt.
LAYOUT_VERSION = 1

CAN_MODULES = ["can", "can-raw", "vcan"]
GPIO_MODULES = ["configfs", "gpio-sim"]
CAN_TOOLS = ["candump", "cansend", "cangen", "cansequence"]
GPIO_TOOLS = ["gpiodetect", "gpioinfo", "gpioget", "gpioset", "gpiomon", "gpiofind"]
GPIO_SIM_LINES = 16
# Names of the first gpio-sim lines (the rest are unnamed): what pathstream wires to GPIO.
GPIO_SIM_NAMES = ["pen-lift", "enable", "estop", "limit-x", "limit-y"]


class HarnessError(Exception):
    pass


def log(msg: str) -> None:
    print(f"run_in_vm: {msg}", flush=True)


# --- kernel cache --------------------------------------------------------------------------------
def default_cache() -> Path:
    """The cache directory setup_vm.sh fills, from the kernel pinned at its top."""
    setup = REPO / "scripts" / "setup_vm.sh"
    abi = None
    if setup.is_file():
        m = re.search(r"^KERNEL_ABI=(\S+)", setup.read_text(), re.M)
        abi = m.group(1) if m else None
    if abi is None:
        raise HarnessError(f"cannot read KERNEL_ABI from {setup}; pass --kernel-cache")
    root = Path(os.environ.get("PATHSTREAM_VM_CACHE", "/var/cache/pathstream-vm"))
    return root / f"{abi}-amd64"


def read_cache(cache: Path) -> dict[str, str]:
    ready = cache / "READY"
    if not ready.is_file():
        raise HarnessError(f"no kernel cache at {cache} (no READY): run scripts/setup_vm.sh")
    info = {}
    for line in ready.read_text().splitlines()[1:]:
        key, _, value = line.partition("=")
        info[key] = value
    for key in ("VMLINUZ", "MODULES_DIR", "KERNEL_RELEASE"):
        if key not in info:
            raise HarnessError(f"{ready} lacks {key}: run scripts/setup_vm.sh again")
    if not Path(info["VMLINUZ"]).is_file() or not (Path(info["MODULES_DIR"]) / "modules.dep").is_file():
        raise HarnessError(f"kernel cache {cache} is incomplete: run scripts/setup_vm.sh")
    # The uncompressed ELF boots through PVH, without firmware or xz under TCG (~4 s faster).
    vmlinux = info.get("VMLINUX", "")
    info["KERNEL"] = vmlinux if vmlinux and Path(vmlinux).is_file() else info["VMLINUZ"]
    info["CACHE"] = str(cache)
    return info


def module_order(moddir: Path, names: list[str]) -> list[str]:
    """Relative paths of the modules NAMES and their dependencies from modules.dep, in load order."""
    deps: dict[str, list[str]] = {}
    by_name: dict[str, str] = {}
    for line in (moddir / "modules.dep").read_text().splitlines():
        if ":" not in line:
            continue
        mod, _, rest = line.partition(":")
        deps[mod] = rest.split()
        base = Path(mod).name.split(".ko")[0].replace("-", "_")
        by_name[base] = mod
    order: list[str] = []

    def visit(mod: str, stack: tuple[str, ...]) -> None:
        if mod in order:
            return
        if mod in stack:
            raise HarnessError(f"module dependency cycle at {mod}")
        for d in deps.get(mod, []):
            visit(d, stack + (mod,))
        order.append(mod)

    for n in names:
        mod = by_name.get(n.replace("-", "_"))
        if mod is None:
            raise HarnessError(f"module {n} is not in {moddir}/modules.dep")
        visit(mod, ())
    return order


# --- files and their libraries ---------------------------------------------------------------------
_LDD_CACHE: dict[str, list] = {}
_LDD_CACHE_FILE: Path | None = None


def load_ldd_cache(path: Path) -> None:
    """ldd answers from earlier runs, keyed by file, size and mtime (ldd costs ~0.1 s a call)."""
    global _LDD_CACHE_FILE
    _LDD_CACHE_FILE = path
    try:
        _LDD_CACHE.update(json.loads(path.read_text()))
    except (OSError, ValueError):
        pass


def save_ldd_cache() -> None:
    if _LDD_CACHE_FILE is not None:
        tmp = _LDD_CACHE_FILE.with_name(_LDD_CACHE_FILE.name + f".tmp{os.getpid()}")
        tmp.write_text(json.dumps(_LDD_CACHE))
        os.replace(tmp, _LDD_CACHE_FILE)


def shared_libraries(exe: Path) -> list[tuple[str, Path]]:
    """(path inside the VM, host file) of every shared library EXE needs, from ldd."""
    st = exe.stat()
    key = str(exe.resolve())
    cached = _LDD_CACHE.get(key)
    if cached and cached[0] == st.st_size and cached[1] == st.st_mtime_ns:
        pairs = cached[2]
    else:
        pairs = _run_ldd(exe)
        _LDD_CACHE[key] = [st.st_size, st.st_mtime_ns, pairs]
    # Resolved now, not when cached: a library upgraded since still shows up.
    return [(vm, Path(host).resolve()) for vm, host in pairs]


def _run_ldd(exe: Path) -> list[list[str]]:
    try:
        out = subprocess.run(["ldd", str(exe)], capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired as e:
        raise HarnessError(f"ldd {exe} timed out") from e
    text = out.stdout + out.stderr
    if "not a dynamic executable" in text or "statically linked" in text:
        return []
    if out.returncode != 0:
        raise HarnessError(f"ldd {exe} failed: {text.strip()}")
    libs = []
    for line in out.stdout.splitlines():
        line = line.strip()
        if "=> not found" in line:
            raise HarnessError(f"{exe}: {line}")
        m = re.match(r"(\S+) => (/\S+) \(0x", line)
        if m:  # libfoo.so.1 => /lib/x86_64-linux-gnu/libfoo.so.1
            libs.append([f"/lib/x86_64-linux-gnu/{m.group(1)}", m.group(2)])
            continue
        m = re.match(r"(/\S+) \(0x", line)
        if m:  # the program interpreter, at the absolute path the ELF names
            libs.append([m.group(1), m.group(1)])
    return libs


def is_elf(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


def stripped_elf(src: Path, scratch: Path) -> bytes:
    """`src` without its debug sections (objcopy --strip-debug); the symbols stay."""
    tmp = scratch / f"strip-{os.getpid()}-{src.name}"
    try:
        proc = subprocess.run(["objcopy", "--strip-debug", str(src), str(tmp)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if proc.returncode != 0:
            raise HarnessError(f"objcopy --strip-debug {src} failed: {proc.stdout.strip()}")
        return tmp.read_bytes()
    finally:
        tmp.unlink(missing_ok=True)


class Tree:
    """Files of one initramfs archive: path inside the VM -> (kind, source or target, mode)."""

    def __init__(self) -> None:
        self.entries: dict[str, tuple[str, str, int]] = {}

    def add_file(self, dest: str, src: Path, mode: int | None = None) -> None:
        if not src.is_file():
            raise HarnessError(f"no such file: {src}")
        if mode is None:
            mode = 0o755 if os.access(src, os.X_OK) else 0o644
        self.entries[dest] = ("file", str(src.resolve()), mode)

    def add_bytes(self, dest: str, data: str, mode: int = 0o644) -> None:
        self.entries[dest] = ("data", data, mode)

    def add_symlink(self, dest: str, target: str) -> None:
        self.entries[dest] = ("link", target, 0o777)

    def add_dir(self, dest: str) -> None:
        self.entries[dest] = ("dir", "", 0o755)

    def add_program(self, dest: str, src: Path) -> None:
        self.add_file(dest, src, 0o755)
        if is_elf(src):
            # Without its debug sections: a RelWithDebInfo pathstream is ~150 MB of which the
            # guest needs ~10, and 512 MB of guest RAM cannot hold the archive and its unpacked
            # copy of that much (the kernel reports "Initramfs unpacking failed: write error").
            self.entries[dest] = ("elf", str(src.resolve()), 0o755)
            for vm_path, host in shared_libraries(src):
                self.add_file(vm_path, host, 0o755)

    def key(self) -> str:
        """A digest of everything that ends up in the archive (file contents by size+mtime+name)."""
        h = hashlib.sha256(f"layout {LAYOUT_VERSION}\n".encode())
        for dest in sorted(self.entries):
            kind, what, mode = self.entries[dest]
            if kind in ("file", "elf"):
                st = os.stat(what)
                what = f"{what} {st.st_size} {st.st_mtime_ns}"
            h.update(json.dumps([dest, kind, what, mode]).encode() + b"\n")
        return h.hexdigest()[:20]

    def write_cpio(self, out: Path) -> None:
        """A newc cpio archive the kernel unpacks as initramfs (parents before children)."""
        dirs = set()
        for dest in self.entries:
            parts = dest.strip("/").split("/")
            for i in range(1, len(parts)):
                dirs.add("/".join(parts[:i]))
        for dest, (kind, _, _) in self.entries.items():
            if kind == "dir":
                dirs.add(dest.strip("/"))
        ino = 1

        def header(name: str, mode: int, size: int, nlink: int) -> bytes:
            nonlocal ino
            ino += 1
            name_b = name.encode() + b"\0"
            fields = [ino, mode, 0, 0, nlink, 0, size, 0, 0, 0, 0, len(name_b), 0]
            h = b"070701" + b"".join(b"%08X" % f for f in fields) + name_b
            return h + b"\0" * (-len(h) % 4)

        tmp = out.with_name(out.name + f".tmp{os.getpid()}")
        with open(tmp, "wb") as f:
            for d in sorted(dirs):
                f.write(header(d, stat.S_IFDIR | 0o755, 0, 2))
            for dest in sorted(self.entries):
                kind, what, mode = self.entries[dest]
                name = dest.strip("/")
                if kind == "dir":
                    continue
                if kind == "link":
                    data = what.encode()
                    f.write(header(name, stat.S_IFLNK | 0o777, len(data), 1))
                else:
                    if kind == "elf":
                        data = stripped_elf(Path(what), out.parent)
                    elif kind == "file":
                        data = Path(what).read_bytes()
                    else:
                        data = what.encode()
                    f.write(header(name, stat.S_IFREG | mode, len(data), 1))
                f.write(data + b"\0" * (-len(data) % 4))
            f.write(header("TRAILER!!!", 0, 0, 1))
            f.write(b"\0" * (-f.tell() % 512))
        os.replace(tmp, out)


def base_tree(info: dict[str, str]) -> Tree:
    """What every VM gets: busybox, the modules, the Debian tools, /init and the helpers."""
    t = Tree()
    busybox = shutil.which("busybox") or "/bin/busybox"
    busybox_path = Path(busybox)
    if not busybox_path.is_file() or shared_libraries(busybox_path):
        raise HarnessError("a static busybox is needed: apt-get install busybox-static")
    t.add_file("/bin/busybox", busybox_path, 0o755)
    st = busybox_path.stat()
    cached = _LDD_CACHE.get("busybox --list")
    if cached and cached[0] == st.st_size and cached[1] == st.st_mtime_ns:
        applets = cached[2]
    else:
        applets = subprocess.run([busybox, "--list"], capture_output=True, text=True, check=True).stdout.split()
        _LDD_CACHE["busybox --list"] = [st.st_size, st.st_mtime_ns, applets]
    for a in applets:
        if a not in ("busybox",):
            t.add_symlink(f"/bin/{a}", "busybox")
    for tool in CAN_TOOLS + GPIO_TOOLS:
        path = shutil.which(tool)
        if path is None:
            raise HarnessError(f"{tool} not found: run scripts/setup.sh (can-utils, gpiod)")
        t.add_program(f"/usr/bin/{tool}", Path(path))
    moddir = Path(info["MODULES_DIR"])
    krel = info["KERNEL_RELEASE"]
    for rel in module_order(moddir, CAN_MODULES + GPIO_MODULES):
        t.add_file(f"/lib/modules/{krel}/{rel}", moddir / rel, 0o644)
    t.add_file("/init", HERE / "init.sh", 0o755)
    t.add_file("/pathstream/vm_lib.sh", HERE / "vm_lib.sh", 0o644)
    for d in ("/proc", "/sys", "/dev", "/tmp", "/run", "/root", "/pathstream/work", "/sbin", "/usr/sbin"):
        t.add_dir(d)
    return t


def test_tree(args: argparse.Namespace, info: dict[str, str]) -> Tree:
    t = Tree()
    for p in args.program:
        src = Path(p)
        t.add_program(f"/pathstream/bin/{src.name}", src)
    for p in args.data:
        src = Path(p)
        if src.is_dir():
            for f in sorted(src.rglob("*")):
                if f.is_file():
                    t.add_file(f"/pathstream/data/{src.name}/{f.relative_to(src)}", f)
        else:
            t.add_file(f"/pathstream/data/{src.name}", src)
    t.add_file("/pathstream/test.sh", Path(args.script), 0o755)
    modules = []
    if args.can:
        modules += CAN_MODULES
    if args.gpio_sim:
        modules += GPIO_MODULES
    order = module_order(Path(info["MODULES_DIR"]), modules) if modules else []
    t.add_bytes("/etc/pathstream-vm/modules", "".join(m + "\n" for m in order))
    cfg = {
        "VM_CAN": "1" if args.can else "0",
        "VM_CAN_IFACES": " ".join(args.can_iface),
        "VM_GPIO_SIM": "1" if args.gpio_sim else "0",
        "VM_GPIO_SIM_LINES": str(GPIO_SIM_LINES),
        "VM_GPIO_SIM_NAMES": " ".join(GPIO_SIM_NAMES),
        "VM_PROGRAM_TIMEOUT": str(args.program_timeout),
        "VM_SCRIPT_TIMEOUT": str(args.script_timeout),
    }
    t.add_bytes("/etc/pathstream-vm/config", "".join(f"export {k}='{v}'\n" for k, v in cfg.items()))
    return t


def build_initrd(args: argparse.Namespace, info: dict[str, str], work: Path) -> Path:
    """The test's initramfs: the shared base archive (cached by its inputs) + the test's own."""
    cache = Path(args.base_cache) if args.base_cache else work / "cache"
    cache.mkdir(parents=True, exist_ok=True)
    # Tests run in parallel and share the base: one builds it, the others wait for it.
    with open(cache / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        load_ldd_cache(cache / "ldd-cache.json")
        base = base_tree(info)
        test = test_tree(args, info)
        save_ldd_cache()
        base_key = base.key() + "-" + hashlib.sha256(info["KERNEL"].encode()).hexdigest()[:8]
        base_file = cache / f"base-{base_key}.cpio"
        if not base_file.is_file():
            t0 = time.monotonic()
            base.write_cpio(base_file)
            log(f"built base initramfs {base_file.name} ({base_file.stat().st_size >> 10} KiB) "
                f"in {time.monotonic() - t0:.2f} s")
            for old in cache.glob("base-*.cpio"):  # keep the cache small
                if old != base_file:
                    old.unlink(missing_ok=True)
        key = base_key + "-" + test.key()
        initrd = work / "initrd.cpio"
        key_file = work / "initrd.key"
        if initrd.is_file() and key_file.is_file() and key_file.read_text() == key:
            log(f"initramfs unchanged ({initrd})")
            return initrd
        t0 = time.monotonic()
        overlay = work / "overlay.cpio"
        test.write_cpio(overlay)
        # The kernel unpacks concatenated archives in order: the test's files over the base.
        tmp = work / "initrd.cpio.tmp"
        with open(tmp, "wb") as out:
            for part in (base_file, overlay):
                with open(part, "rb") as f:
                    shutil.copyfileobj(f, out)
        os.replace(tmp, initrd)
        overlay.unlink()
        key_file.write_text(key)
    log(f"built initramfs {initrd} ({initrd.stat().st_size >> 10} KiB) in {time.monotonic() - t0:.2f} s")
    return initrd


# --- the accelerator -------------------------------------------------------------------------------
KVM_PROBE_TIMEOUT = 10.0  # a KVM guest prints its first kernel line well within a second
KVM_PROBE_LINE = re.compile(r"Linux version \d")
VERDICT_FILE = "accel-verdict.json"


def kvm_accel_option() -> tuple[str, bool]:
    """The -accel value tried for KVM, and whether it was forced through the environment."""
    forced = os.environ.get("PATHSTREAM_VM_KVM_ACCEL", "").strip()
    return (forced, True) if forced else ("kvm", False)


def spawn_qemu(cmd: list[str]) -> subprocess.Popen:
    """qemu with its console (stdout and stderr) on a pipe; it dies with this harness."""
    return subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, preexec_fn=_die_with_parent)


def probe_kvm(qemu: str, info: dict[str, str], accel: str) -> tuple[bool, str]:
    """Boots the kernel alone (no initramfs) under ACCEL; True once it prints its first line.

    A KVM that cannot run the guest makes qemu abort at once or hang silently: both are a
    no. The kernel panics without a root file system and, with -no-reboot, qemu exits.
    """
    cmd = [qemu, "-accel", accel, "-cpu", "host", "-m", "256", "-nographic", "-no-reboot",
           "-monitor", "none", "-nic", "none", "-kernel", info["KERNEL"],
           "-append", "console=ttyS0 panic=-1 loglevel=4"]
    t0 = time.monotonic()
    proc = spawn_qemu(cmd)
    seen: list[str] = []
    tail: list[str] = []

    def pump() -> None:
        assert proc.stdout is not None
        for raw in proc.stdout:
            line = raw.decode("utf-8", errors="replace").strip()
            if KVM_PROBE_LINE.search(line) and not seen:
                seen.append(line)
            elif line:
                tail[:] = (tail + [line])[-3:]

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    while proc.poll() is None and not seen and time.monotonic() - t0 < KVM_PROBE_TIMEOUT:
        time.sleep(0.02)
    if proc.poll() is None:
        proc.kill()
    proc.wait()
    reader.join(timeout=2)
    elapsed = time.monotonic() - t0
    if seen:
        return True, f"the guest kernel started in {elapsed:.2f} s"
    why = tail[-1] if tail else "no output"
    if proc.returncode is not None and elapsed < KVM_PROBE_TIMEOUT:
        return False, f"qemu exited with {proc.returncode} after {elapsed:.2f} s ({why})"
    return False, f"the guest printed nothing within {KVM_PROBE_TIMEOUT:.0f} s ({why})"


def verdict_key(qemu: str, info: dict[str, str], accel: str) -> str:
    """What the verdict depends on: qemu, the kernel, /dev/kvm, the option, this boot."""
    parts = [accel, info["KERNEL"]]
    for path in (qemu, info["KERNEL"], "/dev/kvm"):
        try:
            st = os.stat(path)
            parts.append(f"{path} {st.st_size} {st.st_mtime_ns} {st.st_rdev}")
        except OSError:
            parts.append(f"{path} missing")
    try:
        parts.append(Path("/proc/sys/kernel/random/boot_id").read_text().strip())
    except OSError:
        pass
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()[:20]


def choose_accel(args: argparse.Namespace, qemu: str, info: dict[str, str],
                 cache: Path) -> tuple[str, str]:
    """The -accel value for the test run ("kvm", or the forced option, if it starts, else
    "tcg") and the key of the cached verdict it came from ("" when nothing was probed)."""
    if args.accel == "tcg":
        return "tcg", ""
    accel, forced = kvm_accel_option()
    if args.accel == "auto" and not forced and not os.path.exists("/dev/kvm"):
        return "tcg", ""  # nothing to try: the usual case without nested virtualisation
    key = verdict_key(qemu, info, accel)
    verdict_path = cache / VERDICT_FILE
    cache.mkdir(parents=True, exist_ok=True)
    # Tests start in parallel: one probes, the others wait for its verdict.
    with open(cache / ".accel-lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            verdicts = json.loads(verdict_path.read_text())
        except (OSError, ValueError):
            verdicts = {}
        cached = verdicts.get(key)
        if cached is None:
            ok, why = probe_kvm(qemu, info, accel)
            cached = {"accel": accel if ok else "tcg", "why": why, "tried": accel}
            verdicts[key] = cached
            tmp = verdict_path.with_name(verdict_path.name + f".tmp{os.getpid()}")
            tmp.write_text(json.dumps(verdicts, indent=1))
            os.replace(tmp, verdict_path)
            if ok:
                log(f"accelerator: KVM ({why}); verdict cached in {verdict_path}")
            else:
                log(f"accelerator: KVM (-accel {accel}) cannot start the guest: {why}; "
                    f"using TCG (verdict cached in {verdict_path})")
        elif cached["accel"] == "tcg":
            log(f"accelerator: TCG (cached verdict: -accel {cached['tried']} failed: {cached['why']})")
        else:
            log(f"accelerator: KVM (cached verdict: {cached['why']})")
    if cached["accel"] == "tcg" and args.accel == "kvm":
        raise HarnessError(f"--accel kvm: KVM cannot start the guest ({cached['why']})")
    return cached["accel"], key


def forget_kvm(cache: Path, key: str, why: str) -> None:
    """Records that KVM failed after all (a run that died at start), so later tests use TCG."""
    verdict_path = cache / VERDICT_FILE
    with open(cache / ".accel-lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            verdicts = json.loads(verdict_path.read_text())
        except (OSError, ValueError):
            verdicts = {}
        if key in verdicts:
            verdicts[key].update(accel="tcg", why=why)
        tmp = verdict_path.with_name(verdict_path.name + f".tmp{os.getpid()}")
        tmp.write_text(json.dumps(verdicts, indent=1))
        os.replace(tmp, verdict_path)


# --- the VM ------------------------------------------------------------------------------------------
def _die_with_parent() -> None:
    """Runs in the qemu child: SIGKILL it when this harness dies (ctest timeout, Ctrl-C)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass
    os.setsid()


def find_qemu() -> str:
    qemu = shutil.which("qemu-system-x86_64")
    if qemu is None:
        raise HarnessError("qemu-system-x86_64 not found: run scripts/setup.sh (qemu-system-x86)")
    return qemu


def run_vm(args: argparse.Namespace, info: dict[str, str], initrd: Path, log_path: Path,
           qemu: str, accel: str) -> int | None:
    """Boots the test VM; the script's status, 124/125, or None when a KVM run died at start."""
    append = "console=ttyS0 quiet panic=-1 " + args.append
    cmd = [qemu, "-accel", accel, "-m", str(args.memory), "-nographic", "-no-reboot",
           "-monitor", "none", "-nic", "none", "-kernel", info["KERNEL"], "-initrd", str(initrd),
           "-append", append.strip()]
    if accel != "tcg":
        cmd[3:3] = ["-cpu", "host"]
    cmd += args.qemu_arg
    log("booting " + " ".join(cmd))
    t0 = time.monotonic()
    proc = spawn_qemu(cmd)
    result: list[int] = []
    first_result_at: list[float] = []

    def pump() -> None:
        assert proc.stdout is not None
        with open(log_path, "w", encoding="utf-8", errors="replace") as logf:
            for raw in proc.stdout:
                line = raw.decode("utf-8", errors="replace").replace("\r", "").rstrip("\n")
                # SeaBIOS and the kernel may emit terminal escapes; keep the text readable.
                line = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]|\x1bc", "", line)
                logf.write(line + "\n")
                logf.flush()
                if not args.quiet:
                    print(line, flush=True)
                m = RESULT_RE.search(line)
                if m and not result:
                    result.append(int(m.group(1)))
                    first_result_at.append(time.monotonic() - t0)

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()

    def stop(signum: int, _frame: object) -> None:
        proc.kill()
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    timed_out = False
    deadline = t0 + args.timeout
    while proc.poll() is None:
        now = time.monotonic()
        if result and now - t0 > first_result_at[0] + 10:
            log("the VM printed its result but did not power off within 10 s: killing it")
            proc.kill()
            break
        if now > deadline:
            timed_out = True
            proc.kill()
            break
        time.sleep(0.05)
    proc.wait()
    reader.join(timeout=5)
    elapsed = time.monotonic() - t0
    if result:
        log(f"result rc={result[0]} after {first_result_at[0]:.2f} s (qemu ran {elapsed:.2f} s); "
            f"console log: {log_path}")
        return result[0]
    if timed_out:
        log(f"ERROR: the VM printed no result within {args.timeout} s and was killed; "
            f"console log: {log_path}")
        return 124
    if accel != "tcg" and elapsed < 5:
        return None  # KVM passed the probe but this run died at start: the caller retries
    log(f"ERROR: qemu exited with {proc.returncode} after {elapsed:.2f} s without printing a "
        f"result (kernel panic? /init failed?); console log: {log_path}")
    return 125


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", required=True, help="directory for the initramfs and logs (in the build dir)")
    ap.add_argument("--base-cache", help="directory for the shared base initramfs (default WORK/cache); tests may share it")
    ap.add_argument("--script", required=True, help="sh script run inside the VM (busybox sh)")
    ap.add_argument("--program", action="append", default=[], help="executable copied to /pathstream/bin with its libraries")
    ap.add_argument("--data", action="append", default=[], help="file or directory copied to /pathstream/data")
    ap.add_argument("--gpio-sim", action="store_true", help="create the gpio-sim chip (16 lines, bank pathstream-sim)")
    ap.add_argument("--no-can", dest="can", action="store_false", help="do not load CAN nor bring up vcan0")
    ap.add_argument("--can-iface", action="append", default=None, help="vcan interfaces to create (default vcan0)")
    ap.add_argument("--program-timeout", type=int, default=20, help="default vm_run timeout inside the VM (s)")
    ap.add_argument("--script-timeout", type=int, default=0, help="timeout of the whole test script (s; default --timeout - 15)")
    ap.add_argument("--timeout", type=int, default=90, help="overall timeout of the VM run (s)")
    ap.add_argument("--memory", type=int, default=512, help="VM memory (MiB)")
    ap.add_argument("--append", default="", help="extra kernel command line")
    ap.add_argument("--qemu-arg", action="append", default=[], help="extra qemu argument (repeat for each word)")
    ap.add_argument("--kernel-cache", help="setup_vm.sh's cache dir (default: from scripts/setup_vm.sh)")
    ap.add_argument("--expect-rc", type=int, help="exit 0 iff the script exits with this status")
    ap.add_argument("--log", help="console log file (default WORK/console.log)")
    ap.add_argument("--accel", choices=("auto", "kvm", "tcg"), default="auto",
                    help="auto: KVM if a probe boot starts under it, else TCG (default); "
                         "kvm: KVM or fail; tcg: never KVM")
    ap.add_argument("--no-kvm", dest="accel", action="store_const", const="tcg",
                    help="the same as --accel tcg")
    ap.add_argument("--quiet", action="store_true", help="do not echo the console")
    args = ap.parse_args()
    if args.can_iface is None:
        args.can_iface = ["vcan0"]
    if args.script_timeout <= 0:
        args.script_timeout = max(5, args.timeout - 15)
    try:
        info = read_cache(Path(args.kernel_cache) if args.kernel_cache else default_cache())
        work = Path(args.work)
        work.mkdir(parents=True, exist_ok=True)
        initrd = build_initrd(args, info, work)
        qemu = find_qemu()
        cache = Path(args.base_cache) if args.base_cache else work / "cache"
        accel, key = choose_accel(args, qemu, info, cache)
        log_path = Path(args.log) if args.log else work / "console.log"
        rc = run_vm(args, info, initrd, log_path, qemu, accel)
        if rc is None:
            why = f"a test run under -accel {accel} exited at start without a result"
            if args.accel == "kvm":
                raise HarnessError(why)
            log(f"accelerator: {why}; running it again under TCG (later tests use TCG too)")
            forget_kvm(cache, key, why)
            rc = run_vm(args, info, initrd, log_path, qemu, "tcg")
            assert rc is not None
    except HarnessError as e:
        print(f"run_in_vm: ERROR: {e}", file=sys.stderr, flush=True)
        return 125
    if args.expect_rc is not None:
        ok = rc == args.expect_rc
        log(f"expected rc={args.expect_rc}, got rc={rc}: {'OK' if ok else 'FAIL'}")
        return 0 if ok else 1
    return rc


if __name__ == "__main__":
    sys.exit(main())
