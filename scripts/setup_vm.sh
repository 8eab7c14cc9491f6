#!/usr/bin/env bash
# Prepares the real-kernel test VM (docs/vm.md): Debian's own kernel for qemu-system-x86_64,
# its modules (SocketCAN, vcan, configfs) and the out-of-tree gpio-sim + irq_sim modules that
# Debian's kernel does not build. Everything lands in a cache directory; nothing is fetched at
# build or test time, and the kernel package is unpacked (dpkg -x), never installed.
#
#   scripts/setup_vm.sh            # idempotent; a second run is a fast no-op
#   PATHSTREAM_VM_CACHE=/some/dir scripts/setup_vm.sh    # another cache root
#
# To move to another kernel: pick an ABI whose image, headers and source all exist
#   apt-cache search --names-only 'linux-(image|headers)-6.1.0-[0-9]+-amd64'
#   apt-cache policy linux-image-6.1.0-NN-amd64-unsigned linux-source-6.1
# and change the two lines below (sim/vm/CMakeLists.txt reads them from here).
set -euo pipefail

KERNEL_ABI=6.1.0-50               # linux-image-${KERNEL_ABI}-amd64-unsigned
KERNEL_PKG_VERSION=6.1.176-1      # its Debian version (bookworm 12.x point release)

KREL="${KERNEL_ABI}-amd64"
CACHE_ROOT="${PATHSTREAM_VM_CACHE:-/var/cache/pathstream-vm}"
CACHE="$CACHE_ROOT/$KREL"
HEADERS_DIR="/usr/src/linux-headers-$KREL"
SOURCE_FILES=(drivers/gpio/gpio-sim.c drivers/gpio/gpiolib.h kernel/irq/irq_sim.c)
# In-tree modules the harness needs; their absence means the pinned kernel is unusable.
NEEDED_MODULES=(net/can/can.ko net/can/can-raw.ko drivers/net/can/dev/can-dev.ko
                drivers/net/can/vcan.ko fs/configfs/configfs.ko)
# Bump when the way the cache is built changes, so existing caches are rebuilt.
CACHE_FORMAT=2

say() { echo "setup_vm: $*"; }
die() { echo "setup_vm: error: $*" >&2; exit 1; }

if [ "$(id -u)" -ne 0 ]; then sudo=sudo; else sudo=; fi

stamp="$CACHE/READY"
want_stamp="format=$CACHE_FORMAT kernel=$KREL package=$KERNEL_PKG_VERSION"
cache_ready() {  # the stamp of this very setup, and the artefacts the harness uses
  [ -f "$stamp" ] && [ "$(head -n1 "$stamp")" = "$want_stamp" ] &&
    [ -f "$CACHE/vmlinux" ] && [ -f "$CACHE/root/lib/modules/$KREL/modules.dep" ] &&
    [ -f "$CACHE/root/lib/modules/$KREL/extra/gpio-sim.ko" ]
}
if cache_ready; then
  say "kernel $KREL ($KERNEL_PKG_VERSION) ready in $CACHE (nothing to do)"
  exit 0
fi

t_start=$(date +%s)
$sudo mkdir -p "$CACHE_ROOT"
$sudo chown "$(id -u):$(id -g)" "$CACHE_ROOT" 2>/dev/null || true
mkdir -p "$CACHE"
# One setup at a time (several engineers and CI may share the machine).
exec 9>"$CACHE_ROOT/.lock"
flock -w 900 9 || die "another setup_vm.sh holds $CACHE_ROOT/.lock for more than 15 minutes"
if cache_ready; then
  say "kernel $KREL ready in $CACHE (built by a concurrent run)"
  exit 0
fi
rm -f "$stamp"

# --- 1. The pinned packages must be known to apt --------------------------------------------
image_pkg="linux-image-$KREL-unsigned"
headers_pkg="linux-headers-$KREL"
source_pkg="linux-source-6.1"
have_versions() {
  for p in "$image_pkg" "$headers_pkg" "$source_pkg"; do
    apt-cache show "$p=$KERNEL_PKG_VERSION" >/dev/null 2>&1 || return 1
  done
}
if ! have_versions; then
  say "refreshing apt lists"
  $sudo apt-get update -q >/dev/null
fi
if ! have_versions; then
  for p in "$image_pkg" "$headers_pkg" "$source_pkg"; do
    apt-cache show "$p=$KERNEL_PKG_VERSION" >/dev/null 2>&1 ||
      echo "setup_vm: missing from apt: $p=$KERNEL_PKG_VERSION" >&2
  done
  die "the pinned kernel $KREL ($KERNEL_PKG_VERSION) is no longer in the apt lists; pick one
  whose image, headers and source exist (see the comment at the top of $0), e.g.:
$(apt-cache search --names-only "linux-headers-6.1.0-[0-9]+-amd64" | sed 's/^/    /')"
fi

# --- 2. Headers (installed: they are only headers) ------------------------------------------
if ! dpkg-query -W -f='${Status} ${Version}' "$headers_pkg" 2>/dev/null |
     grep -q "install ok installed $KERNEL_PKG_VERSION"; then
  say "installing $headers_pkg=$KERNEL_PKG_VERSION"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends \
    "$headers_pkg=$KERNEL_PKG_VERSION" >/dev/null
else
  say "$headers_pkg already installed"
fi
[ -f "$HEADERS_DIR/Makefile" ] || die "$HEADERS_DIR/Makefile missing after installing $headers_pkg"

# --- 3. Kernel image and modules: downloaded and unpacked, not installed --------------------
debs="$CACHE/debs"
root="$CACHE/root"
mkdir -p "$debs"
fetch() {  # fetch PACKAGE: the .deb of the pinned version into $debs, echo its path
  local f
  f=$(ls "$debs/$1_"*.deb 2>/dev/null | head -n1 || true)
  if [ -z "$f" ]; then
    say "downloading $1=$KERNEL_PKG_VERSION" >&2
    (cd "$debs" && apt-get download -q "$1=$KERNEL_PKG_VERSION" >/dev/null 2>&1) ||
      (cd "$debs" && apt-get download "$1=$KERNEL_PKG_VERSION" >&2) ||
      die "apt-get download $1=$KERNEL_PKG_VERSION failed"
    f=$(ls "$debs/$1_"*.deb | head -n1)
  fi
  echo "$f"
}
vmlinuz="$root/boot/vmlinuz-$KREL"
moddir="$root/lib/modules/$KREL"
if [ ! -f "$vmlinuz" ] || [ ! -f "$moddir/modules.order" ]; then
  deb=$(fetch "$image_pkg")
  say "unpacking $(basename "$deb") into $root"
  rm -rf "$root"
  dpkg -x "$deb" "$root"
else
  say "kernel image already unpacked in $root"
fi
[ -f "$vmlinuz" ] || die "no $vmlinuz in $image_pkg"
[ -d "$moddir/kernel" ] || die "no $moddir/kernel in $image_pkg"
for m in "${NEEDED_MODULES[@]}"; do
  ls "$moddir/kernel/$m"* >/dev/null 2>&1 || die "kernel $KREL lacks module $m"
done

# --- 4. The three source files from linux-source (only those are extracted) -----------------
src="$CACHE/src"
missing_src=0
for f in "${SOURCE_FILES[@]}"; do [ -f "$src/$f" ] || missing_src=1; done
if [ "$missing_src" = 1 ]; then
  deb=$(fetch "$source_pkg")
  say "extracting ${SOURCE_FILES[*]} from $(basename "$deb") (decompresses the whole tarball)"
  tmp="$CACHE/src.tmp"
  rm -rf "$tmp"; mkdir -p "$tmp"
  members=()
  for f in "${SOURCE_FILES[@]}"; do members+=("linux-source-6.1/$f"); done
  dpkg-deb --fsys-tarfile "$deb" |
    tar -xO ./usr/src/linux-source-6.1.tar.xz |
    tar -xJ -C "$tmp" "${members[@]}"
  rm -rf "$src"
  mv "$tmp/linux-source-6.1" "$src"
  rm -rf "$tmp"
  for f in "${SOURCE_FILES[@]}"; do [ -f "$src/$f" ] || die "$f not found in $source_pkg"; done
else
  say "sources already extracted in $src"
fi

# --- 5. Out-of-tree irq_sim.ko and gpio-sim.ko ----------------------------------------------
oot="$CACHE/oot"
if [ ! -f "$oot/irq_sim.ko" ] || [ ! -f "$oot/gpio-sim.ko" ]; then
  say "building irq_sim.ko and gpio-sim.ko against $HEADERS_DIR"
  rm -rf "$oot"; mkdir -p "$oot"
  cp "$src/drivers/gpio/gpio-sim.c" "$src/drivers/gpio/gpiolib.h" "$oot/"
  # irq_sim is built-in only (CONFIG_IRQ_SIM, not set in Debian's kernel): as a module it
  # cannot reach handle_simple_irq(irq_to_desc(n)) (irq_to_desc is not exported), and
  # generic_handle_irq(n) is the exported equivalent; a module also needs a licence.
  sed 's/handle_simple_irq(irq_to_desc(\([^)]*\)))/generic_handle_irq(\1)/' \
    "$src/kernel/irq/irq_sim.c" > "$oot/irq_sim.c"
  grep -q 'generic_handle_irq(' "$oot/irq_sim.c" ||
    die "irq_sim.c: the handle_simple_irq(irq_to_desc(...)) call to patch was not found"
  if grep -q 'irq_to_desc' "$oot/irq_sim.c"; then
    die "irq_sim.c still calls irq_to_desc after patching"
  fi
  printf '\nMODULE_LICENSE("GPL");\nMODULE_DESCRIPTION("interrupt simulator (out of tree, pathstream test VM)");\n' \
    >> "$oot/irq_sim.c"
  printf 'obj-m := irq_sim.o gpio-sim.o\n' > "$oot/Kbuild"
  if ! make -C "$HEADERS_DIR" M="$oot" -j"$(nproc)" modules > "$oot/build.log" 2>&1; then
    tail -n 40 "$oot/build.log" >&2
    die "building the out-of-tree modules failed (log: $oot/build.log)"
  fi
  for k in irq_sim.ko gpio-sim.ko; do
    [ -f "$oot/$k" ] || die "$k was not built (log: $oot/build.log)"
  done
else
  say "out-of-tree modules already built in $oot"
fi

# --- 6. modules.dep (the package leaves it to depmod in its postinst), extra/ included -------
if [ ! -f "$moddir/modules.dep" ] || [ ! -f "$moddir/extra/gpio-sim.ko" ] ||
   [ "$oot/gpio-sim.ko" -nt "$moddir/modules.dep" ] || [ "$oot/irq_sim.ko" -nt "$moddir/modules.dep" ]; then
  mkdir -p "$moddir/extra"
  cp "$oot/irq_sim.ko" "$oot/gpio-sim.ko" "$moddir/extra/"
  say "running depmod for $KREL (busybox depmod -b $root)"
  busybox depmod -b "$root" "$KREL" || die "depmod failed"
fi
grep -q '^extra/gpio-sim.ko:.*extra/irq_sim.ko' "$moddir/modules.dep" ||
  die "modules.dep does not show gpio-sim depending on irq_sim"

# --- 7. vmlinux: the uncompressed ELF, booted by qemu through PVH (CONFIG_PVH=y): no
# firmware, no in-guest xz decompression; halves boot time under TCG -----------------------------
vmlinux="$CACHE/vmlinux"
if [ ! -f "$vmlinux" ] || [ "$vmlinuz" -nt "$vmlinux" ]; then
  say "extracting vmlinux (ELF, for qemu's PVH boot) from $(basename "$vmlinuz")"
  /usr/bin/python3 - "$vmlinuz" "$vmlinux.tmp" <<'PY' || die "cannot extract vmlinux from $vmlinuz"
import lzma, sys
data = open(sys.argv[1], "rb").read()
start = data.find(b"\xfd7zXZ\x00")
if start < 0:
    sys.exit("no xz stream in the bzImage (not CONFIG_KERNEL_XZ?)")
elf = lzma.LZMADecompressor().decompress(data[start:])
if elf[:4] != b"\x7fELF":
    sys.exit("the xz payload is not an ELF image")
open(sys.argv[2], "wb").write(elf)
PY
  mv "$vmlinux.tmp" "$vmlinux"
fi

# --- 8. Done: drop the downloads, write the stamp -------------------------------------------
rm -rf "$debs"
{
  echo "$want_stamp"
  echo "KERNEL_RELEASE=$KREL"
  echo "KERNEL_PACKAGE_VERSION=$KERNEL_PKG_VERSION"
  echo "VMLINUZ=$vmlinuz"
  echo "VMLINUX=$vmlinux"
  echo "MODULES_DIR=$moddir"
  echo "OOT_BUILD_DIR=$oot"
} > "$stamp"
say "kernel $KREL ($KERNEL_PKG_VERSION) ready in $CACHE in $(( $(date +%s) - t_start )) s:"
sed -n '2,$p' "$stamp" | sed 's/^/  /'
