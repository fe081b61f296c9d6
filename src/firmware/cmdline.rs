//! The firmware's mode, from the semihosting command line.
//!
//! One ELF, two missions: the built-in replay ([`super::mission`], the default) and the
//! processor-in-the-loop link ([`super::pil`]), chosen by the word `pil` on the command line
//! the debugger or emulator passes through semihosting (`SYS_GET_CMDLINE`). In QEMU that is
//! `-append pil` (QEMU hands the guest `<kernel file> <append>`); `scripts/qemu-run` passes
//! nothing, so the replay runs. Like the defmt log, this needs a semihosting host (QEMU or a
//! debug probe); a flight unit without one would take its mode from its own configuration.

/// Which mission the firmware runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Mode {
    /// The built-in replay of the paper's first 900 s (`expected/firmware.log`).
    Replay,
    /// Processor-in-the-loop: sensor samples in and commands out over UART0.
    Pil,
}

/// Semihosting operation number of `SYS_GET_CMDLINE` (Arm semihosting specification).
const SYS_GET_CMDLINE: usize = 0x15;

/// Room for the command line (the kernel's path and the appended words).
const CMDLINE_MAX: usize = 256;

/// The word on the command line that selects [`Mode::Pil`].
pub const PIL_WORD: &[u8] = b"pil";

/// The mode the command line asks for: [`Mode::Pil`] if a word after the first (the program's
/// name) is [`PIL_WORD`], else [`Mode::Replay`].
pub fn mode() -> Mode {
    let mut buf = [0u8; CMDLINE_MAX];
    let Some(line) = read(&mut buf) else {
        return Mode::Replay;
    };
    let pil = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .skip(1)
        .any(|w| w == PIL_WORD);
    if pil {
        Mode::Pil
    } else {
        Mode::Replay
    }
}

/// The semihosting command line, without its NUL, or `None` if the host gave none.
fn read(buf: &mut [u8; CMDLINE_MAX]) -> Option<&[u8]> {
    // The parameter block of SYS_GET_CMDLINE: buffer address and size; the host writes the
    // length of the line into the second word.
    let mut block: [usize; 2] = [buf.as_mut_ptr() as usize, CMDLINE_MAX];
    // SAFETY: a semihosting call (`bkpt 0xab`) with r1 = the address of `block`, a live,
    // aligned two-word parameter block that points to `buf`, `CMDLINE_MAX` bytes we own
    // exclusively here. The host writes at most that many bytes into `buf` and one word into
    // `block`; nothing else is touched. Both are read only after the call returns.
    #[allow(unsafe_code)]
    let status =
        unsafe { cortex_m_semihosting::syscall1(SYS_GET_CMDLINE, block.as_mut_ptr() as usize) };
    if status != 0 {
        return None;
    }
    let reported = block[1].min(CMDLINE_MAX);
    let line = buf.get(..reported)?;
    let end = line.iter().position(|&b| b == 0).unwrap_or(line.len());
    line.get(..end)
}
