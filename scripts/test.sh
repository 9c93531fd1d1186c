#!/usr/bin/env bash
# Runs the test suite. Installs Mesa's software Vulkan driver (lavapipe) and the Vulkan loader
# first when they are missing and apt is available, so GPU tests can run without a GPU; and
# Slurm with MUNGE, for the test that runs a sweep's job array on a single-node Slurm it starts
# itself (tests/sweep/; with CI set it fails rather than skips when they are missing).
#
# On Debian 12 lavapipe comes from bookworm-backports (Mesa 25) when that suite can be reached:
# Mesa 22.3's lavapipe, the stock one, runs our compute shaders about three times slower (it
# compiles every storage-buffer access into a loop over the SIMD lanes; see
# docs/guide/src/benchmarks.md, "What lavapipe charges for, measured (Mesa 22.3)"). The
# stock package is the fallback; the tests pass on both.
set -euo pipefail
cd "$(dirname "$0")/.."

# The archive that serves this machine's "bookworm" suite (deb822 or one-line sources): the
# backports suite lives beside it, so no mirror is named here.
debian_main_uri() {
  local f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && awk '/^URIs:/ {u=$2} /^Suites:/ {for (i = 2; i <= NF; i++) if ($i == "bookworm") print u}' "$f"
  done
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] && awk '$1 == "deb" && $3 == "bookworm" {print $2}' "$f"
  done
  return 0
}

install_lavapipe() {
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  local packages=(mesa-vulkan-drivers libvulkan1)
  $sudo apt-get update -q
  if grep -q '^VERSION_CODENAME=bookworm$' /etc/os-release 2>/dev/null; then
    if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
      local uri
      uri=$(debian_main_uri | head -n 1)
      if [ -z "$uri" ]; then
        echo "note: no Debian main archive in the apt sources; using Debian 12's own lavapipe" >&2
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "${packages[@]}"
        return
      fi
      printf '%s\n' 'Types: deb' "URIs: $uri" \
        'Suites: bookworm-backports' 'Components: main' \
        'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg' |
        $sudo tee /etc/apt/sources.list.d/dustdem-bookworm-backports.sources >/dev/null
      $sudo apt-get update -q || true
    fi
    if DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q -t bookworm-backports "${packages[@]}"; then
      return
    fi
    echo "note: lavapipe from bookworm-backports failed; installing Debian 12's own" >&2
  fi
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "${packages[@]}"
}

if ! ldconfig -p 2>/dev/null | grep -q libvulkan.so.1 || ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
  if command -v apt-get >/dev/null 2>&1; then
    install_lavapipe
  else
    echo "note: no apt-get; install Mesa's Vulkan drivers (lavapipe) yourself for the GPU tests" >&2
  fi
fi

# The Slurm daemons, client and MUNGE from the distribution. The test starts its own daemons
# (its own key, socket, ports and config under a temporary directory) and stops them; nothing
# here is configured or started. Without recommends: the plugin development packages are not
# needed.
install_slurm() {
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends \
    slurmctld slurmd slurm-client munge
}

have_program() {
  command -v "$1" >/dev/null 2>&1 || [ -x "/usr/sbin/$1" ] || [ -x "/sbin/$1" ]
}

if ! have_program slurmctld || ! have_program slurmd || ! have_program sbatch || ! have_program munged; then
  if command -v apt-get >/dev/null 2>&1; then
    install_slurm
  else
    echo "note: no apt-get; install Slurm (slurmctld, slurmd, client) and MUNGE yourself for the Slurm test" >&2
  fi
fi

# Mesa's device-select layer makes libwayland complain without a runtime directory (the GPU
# tests probe for an adapter in-process); give the tests a private one, removed at exit.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
  XDG_RUNTIME_DIR="$(mktemp -d -t dustdem-runtime.XXXXXX)"
  export XDG_RUNTIME_DIR
  trap 'rm -rf "$XDG_RUNTIME_DIR"' EXIT
fi
# --- User guide (mdBook) ---------------------------------------------------------------------
# Builds docs/guide into docs/guide/book; a chapter missing from SUMMARY.md or a broken include
# fails the build (create-missing = false). Links are checked by tests/guide_links.rs below.
# mdbook is installed through cargo when missing (0.4.52 needs Rust 1.82 or newer).
MDBOOK_VERSION=0.4.52
mdbook=mdbook
if ! command -v mdbook >/dev/null 2>&1; then
  cargo install mdbook --locked --version "$MDBOOK_VERSION"
  mdbook="${CARGO_HOME:-$HOME/.cargo}/bin/mdbook"
fi
"$mdbook" build docs/guide
# --- end of user guide ----------------------------------------------------------------------

# --- Python package (python/: PyO3 extension + pure-Python layer, built with maturin) ---------
# A virtual environment under target/ with maturin, numpy, pytest, matplotlib and pandas; the
# extension is built into it (sharing target/ with the crate), then python/tests run against
# the dustdem program built here, whose runs they compare with (examples/phi_p.py included).
# Debian's python3 needs python3-venv for `python3 -m venv`; it is installed when missing.
pyenv=target/pyenv
if [ ! -x "$pyenv/bin/pip" ]; then
  rm -rf "$pyenv"
  if ! python3 -m venv "$pyenv"; then
    rm -rf "$pyenv"
    if command -v apt-get >/dev/null 2>&1; then
      sudo=""
      [ "$(id -u)" -ne 0 ] && sudo="sudo"
      py=$(python3 -c 'import sys; print("python%d.%d" % sys.version_info[:2])')
      $sudo apt-get update -q
      DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q "$py-venv" ||
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q python3-venv
    fi
    python3 -m venv "$pyenv"
  fi
fi
"$pyenv/bin/python" -m pip install -q --disable-pip-version-check \
  maturin numpy pytest matplotlib pandas
cargo build --release --bin dustdem
VIRTUAL_ENV="$PWD/$pyenv" "$pyenv/bin/maturin" develop --release -m python/Cargo.toml
DUSTDEM_EXE="$PWD/target/release/dustdem" "$pyenv/bin/python" -m pytest python/tests -q
# --- end of Python package ------------------------------------------------------------------

cargo test --release "$@"
