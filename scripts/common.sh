# shellcheck shell=bash
# Shared helpers of the project's scripts. Source it: `source "$(dirname "$0")/common.sh"`.
# It moves to the repository root, so every script works from any working directory.

REPO_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$REPO_ROOT" || exit 1

# Tools installed by `cargo install` land in $CARGO_HOME/bin; make sure this shell finds them.
CARGO_BIN_DIR=${CARGO_HOME:-$HOME/.cargo}/bin
case ":$PATH:" in
  *":$CARGO_BIN_DIR:"*) ;;
  *) export PATH="$CARGO_BIN_DIR:$PATH" ;;
esac

# The firmware's target, the package feature every MCU program needs (Cargo.toml), its flight
# build and where that build lands.
FW_TARGET=thumbv7em-none-eabihf
FW_FEATURES=firmware
FW_PROFILE=firmware
# shellcheck disable=SC2034 # used by the scripts that source this file
FW_ELF=target/$FW_TARGET/$FW_PROFILE/tss-reel

# The compile-time defmt filter the expected log is made with (see .cargo/config.toml).
export DEFMT_LOG=info

# step NAME COMMAND...: run one step, print a banner before and its duration after.
step() {
  local name=$1
  shift
  local start=$SECONDS
  printf '\n==> %s\n' "$name"
  "$@"
  printf '==> %s: ok (%ss)\n' "$name" "$((SECONDS - start))"
}

# A tool from the toolchain's llvm-tools component (llvm-size, llvm-nm), which is not on PATH.
llvm_tool() {
  local name=$1 sysroot found
  sysroot=$(rustc --print sysroot)
  for found in "$sysroot"/lib/rustlib/*/bin/"$name"; do
    if [[ -x $found ]]; then
      printf '%s\n' "$found"
      return 0
    fi
  done
  echo "error: $name not found in $sysroot/lib/rustlib/*/bin (is the llvm-tools component installed? run scripts/setup)" >&2
  return 1
}

# Builds the flight firmware (profile `firmware`).
build_firmware() {
  cargo build --profile "$FW_PROFILE" --target "$FW_TARGET" --features "$FW_FEATURES" --bin tss-reel
}

# The real board's firmware (NUCLEO-G474RE, src/board/nucleo_g474re.rs): its feature, bin and
# flight ELF (same target and profile; `cargo fw-board` builds the same thing). It cannot run
# here: the scripts build, lint and measure it.
BOARD_FEATURES=nucleo-g474re
BOARD_BIN=tss-reel-nucleo-g474re
# shellcheck disable=SC2034 # used by the scripts that source this file
BOARD_ELF=target/$FW_TARGET/$FW_PROFILE/$BOARD_BIN
# The board's control path for scripts/panic-check: the outer law's cycle (and its period
# after the replay), the on-board computer's link (the main loop's reads, the USART2
# interrupt) and the inner loop.
# shellcheck disable=SC2034
BOARD_PANIC_ROOT='^(tss_reel_nucleo_g474re::board::Outer::(control|idle|listen)(::h[0-9a-f]+)?|SysTick|USART2)$'

# Builds the board's flight firmware (profile `firmware`).
build_board() {
  cargo build --profile "$FW_PROFILE" --target "$FW_TARGET" --features "$BOARD_FEATURES" --bin "$BOARD_BIN"
}

# apt_install PACKAGE...: installs Debian packages with apt-get (as root, else through sudo),
# without a prompt.
apt_install() {
  local sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    if ! command -v sudo >/dev/null 2>&1; then
      echo "error: $* missing and we are not root; install them with your package manager" >&2
      return 1
    fi
    sudo=(sudo)
  fi
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "$@"
}

# Slurm and MUNGE, for the campaign test on a one-node Slurm (scripts/slurm-test): installs the
# Debian packages whose programs are missing. Only the programs: the test runs daemons of its
# own, with its own configuration, and stops them.
ensure_slurm() {
  local missing=() pair program
  for pair in slurmctld:slurmctld slurmd:slurmd sbatch:slurm-client munged:munge; do
    program=${pair%%:*}
    if ! command -v "$program" >/dev/null 2>&1 && [[ ! -x /usr/sbin/$program ]]; then
      missing+=("${pair#*:}")
    fi
  done
  if [[ ${#missing[@]} -gt 0 ]]; then
    echo "installing ${missing[*]} (apt-get)"
    apt_install "${missing[@]}"
  else
    echo "slurmctld, slurmd, sbatch and munged present: $(slurmctld -V 2>/dev/null || /usr/sbin/slurmctld -V)"
  fi
}
