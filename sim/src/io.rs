//! Bounded file reads: every file rover reads goes through here, so a device, a FIFO or a huge
//! file is an error naming it rather than a hang or an exhausted memory.

use std::path::Path;

use crate::error::{Result, SimError};

/// Largest text file rover reads (robot descriptions, xacro includes, worlds, scripts).
pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;

/// Reads a regular file of at most `max_bytes`. A device, FIFO or folder (`/dev/zero` named as
/// an include or mesh would otherwise be read forever) and a larger file are errors naming it.
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let io = |source| SimError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(SimError::invalid(
            path,
            None,
            "not a regular file: expected a file to read",
        ));
    }
    if meta.len() > max_bytes {
        return Err(SimError::invalid(
            path,
            None,
            format!("file is {} bytes; expected at most {max_bytes}", meta.len()),
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(SimError::invalid(
            path,
            None,
            format!("file grew past {max_bytes} bytes while being read"),
        ));
    }
    Ok(bytes)
}

/// Reads a UTF-8 text file of at most [`MAX_TEXT_FILE_BYTES`] (see [`read_bounded`]).
pub fn read_text(path: &Path) -> Result<String> {
    String::from_utf8(read_bounded(path, MAX_TEXT_FILE_BYTES)?).map_err(|e| SimError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        ),
    })
}
