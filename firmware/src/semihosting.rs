//! Host services over Arm semihosting (QEMU `-semihosting-config enable=on,target=native`):
//! the command line, reading host files, and the exit status.
//!
//! Every call traps into QEMU and blocks the CPU until the host has answered; they are meant
//! for the emulator's replay source and for ending the run, not for a real board.

use cortex_m_semihosting::{debug, nr, syscall, syscall1};

/// Longest host path accepted by [`HostFile::open`], in bytes.
pub const MAX_PATH_LEN: usize = 255;

/// A semihosting call that failed; `errno` is the host's `errno` where it gives one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum HostError {
    /// SYS_GET_CMDLINE failed (no command line, or longer than the buffer).
    CommandLine,
    /// The command line is not UTF-8.
    CommandLineNotUtf8,
    /// The path is longer than [`MAX_PATH_LEN`] bytes.
    PathTooLong,
    /// SYS_OPEN failed.
    Open {
        /// Host errno.
        errno: usize,
    },
    /// SYS_FLEN failed.
    Length {
        /// Host errno.
        errno: usize,
    },
    /// SYS_READ failed.
    Read {
        /// Host errno.
        errno: usize,
    },
}

fn errno() -> usize {
    // SAFETY: SYS_ERRNO takes no argument.
    unsafe { syscall1(nr::ERRNO, 0) }
}

/// The command line QEMU passes to the program (SYS_GET_CMDLINE): the `arg=` values of
/// `-semihosting-config`, joined by spaces, or `-kernel` and `-append` without them.
pub fn command_line(buf: &mut [u8]) -> Result<&str, HostError> {
    // Argument block: buffer address and size; the host writes the command line and its
    // length (without the terminating NUL) back into it.
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: the block and the buffer it names outlive the call; the host writes at most
    // `buf.len()` bytes into the buffer and one word into the block.
    let status = unsafe { syscall1(nr::GET_CMDLINE, block.as_mut_ptr() as usize) };
    if status != 0 || block[1] > buf.len() {
        return Err(HostError::CommandLine);
    }
    core::str::from_utf8(&buf[..block[1]]).map_err(|_| HostError::CommandLineNotUtf8)
}

/// A host file open for reading (closed when dropped).
pub struct HostFile {
    handle: usize,
}

impl HostFile {
    /// Opens `path` (relative paths are relative to QEMU's working directory) in binary
    /// read mode.
    pub fn open(path: &str) -> Result<Self, HostError> {
        let mut name = [0u8; MAX_PATH_LEN + 1];
        let bytes = path.as_bytes();
        if bytes.len() > MAX_PATH_LEN {
            return Err(HostError::PathTooLong);
        }
        name[..bytes.len()].copy_from_slice(bytes);
        // SYS_OPEN wants a NUL-terminated name and its length without the NUL.
        // SAFETY: `name` outlives the call and is NUL-terminated.
        let handle = unsafe {
            syscall(
                nr::OPEN,
                &[name.as_ptr() as usize, nr::open::R_BINARY, bytes.len()],
            )
        };
        if handle as isize == -1 {
            return Err(HostError::Open { errno: errno() });
        }
        Ok(Self { handle })
    }

    /// The file's length in bytes (SYS_FLEN).
    pub fn len_bytes(&self) -> Result<usize, HostError> {
        // SAFETY: SYS_FLEN takes the handle.
        let len = unsafe { syscall(nr::FLEN, &[self.handle]) };
        if len as isize == -1 {
            return Err(HostError::Length { errno: errno() });
        }
        Ok(len)
    }

    /// Reads up to `buf.len()` bytes; returns how many were read, 0 at the end of the file.
    pub fn read(&mut self, buf: &mut [u8]) -> Result<usize, HostError> {
        // SAFETY: the host writes at most `buf.len()` bytes into `buf`.
        let not_read = unsafe {
            syscall(
                nr::READ,
                &[self.handle, buf.as_mut_ptr() as usize, buf.len()],
            )
        };
        if not_read > buf.len() {
            return Err(HostError::Read { errno: errno() });
        }
        Ok(buf.len() - not_read)
    }

    /// Reads until `buf` is full or the file ends; returns how many bytes were read.
    pub fn read_full(&mut self, buf: &mut [u8]) -> Result<usize, HostError> {
        let mut filled = 0;
        while filled < buf.len() {
            let n = self.read(&mut buf[filled..])?;
            if n == 0 {
                break;
            }
            filled += n;
        }
        Ok(filled)
    }
}

impl Drop for HostFile {
    fn drop(&mut self) {
        // SAFETY: SYS_CLOSE takes the handle, which is not used again. A failed close of a
        // read-only file loses nothing, so its status is ignored.
        let _ = unsafe { syscall(nr::CLOSE, &[self.handle]) };
    }
}

/// Ends the emulation: QEMU exits with status 0 if `success`, else 1 (SYS_EXIT with
/// ADP_Stopped_ApplicationExit or ADP_Stopped_RunTimeErrorUnknown).
pub fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached without a semihosting host (e.g. a debugger that ignores SYS_EXIT).
    loop {
        cortex_m::asm::wfi();
    }
}
