//! Reading input files with bounded cost: what a command reads must be a regular file (or, for a
//! CSV, a pipe such as `--csv <(…)`) of bounded size, so that `/dev/zero`, a FIFO where a
//! configuration is expected or a 50 MB configuration is a quick one-line error, not a process
//! that reads until memory runs out. Errors are `std::io::Error`s whose text says what is wrong;
//! each crate's loader wraps them with the path as it does any I/O error.

use std::io::Read;
use std::path::Path;

/// The largest JSON file read (configuration, model, table): 8 MiB, a thousand times the largest
/// the project ships.
pub const MAX_JSON_BYTES: u64 = 8 << 20;
/// The largest CSV read: 1 GiB (the Neural-Fly flights are 1 to 3 MB).
pub const MAX_CSV_BYTES: u64 = 1 << 30;
/// The largest shard result read (`shard.json` of `learn … --shard K/N`, machine-written JSON that
/// carries each item's traces for the figures): 1 GiB.
pub const MAX_SHARD_BYTES: u64 = 1 << 30;
/// The largest ULog flight log read: 1 GiB (a PX4 log of an hour at the default profile is
/// about 100 MB; the reader holds the file and its topics' rows in memory once each).
pub const MAX_ULOG_BYTES: u64 = 1 << 30;
/// The most columns a CSV may have (the Neural-Fly logs have about 20).
pub const MAX_CSV_COLUMNS: usize = 10_000;

/// What a file is read as, which sets its limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    /// A JSON file: a regular file of at most [`MAX_JSON_BYTES`].
    Json,
    /// A CSV file: a regular file or a pipe, of at most [`MAX_CSV_BYTES`].
    Csv,
    /// A shard result: a regular JSON file of at most [`MAX_SHARD_BYTES`].
    ShardResult,
    /// A PX4 ULog flight log: a regular file of at most [`MAX_ULOG_BYTES`].
    Ulog,
}

impl InputKind {
    fn limit(self) -> u64 {
        match self {
            Self::Json => MAX_JSON_BYTES,
            Self::Csv => MAX_CSV_BYTES,
            Self::ShardResult => MAX_SHARD_BYTES,
            Self::Ulog => MAX_ULOG_BYTES,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Json => "a JSON file",
            Self::Csv => "a CSV file",
            Self::ShardResult => "a shard result",
            Self::Ulog => "a ULog file",
        }
    }
}

fn refused(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message)
}

/// Reads the bytes of `path` as `kind`: refuses what is not a regular file (a pipe is accepted
/// for a CSV) and anything larger than the kind's limit, before or while reading.
pub fn read_bytes(path: &Path, kind: InputKind) -> std::io::Result<Vec<u8>> {
    let capacity = std::fs::metadata(path)
        .ok()
        .filter(std::fs::Metadata::is_file)
        .map_or(0, |metadata| metadata.len().min(kind.limit()) as usize);
    let mut bytes = Vec::with_capacity(capacity);
    open(path, kind)?.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Opens `path` as `kind` to be read in pieces: refuses what is not a regular file (a pipe is
/// accepted for a CSV) and a file larger than the kind's limit at once; reading past the limit
/// (a pipe, a growing file) is an error of the read that passes it.
pub fn open(path: &Path, kind: InputKind) -> std::io::Result<BoundedFile> {
    if path.as_os_str().is_empty() {
        return Err(refused("an empty path names no file".to_string()));
    }
    let metadata = std::fs::metadata(path)?;
    check_file_type(&metadata.file_type(), kind)?;
    if metadata.is_file() && metadata.len() > kind.limit() {
        return Err(too_large(metadata.len(), kind));
    }
    Ok(BoundedFile {
        file: std::fs::File::open(path)?.take(kind.limit() + 1),
        kind,
        read: 0,
    })
}

/// A file opened by [`open`]: its reads fail once more than its kind's limit has been read.
pub struct BoundedFile {
    file: std::io::Take<std::fs::File>,
    kind: InputKind,
    read: u64,
}

impl Read for BoundedFile {
    fn read(&mut self, buffer: &mut [u8]) -> std::io::Result<usize> {
        let count = self.file.read(buffer)?;
        self.read += count as u64;
        if self.read > self.kind.limit() {
            return Err(too_large(self.read, self.kind));
        }
        Ok(count)
    }
}

/// Reads `path` as UTF-8 text of `kind` (see [`read_bytes`]).
pub fn read_text(path: &Path, kind: InputKind) -> std::io::Result<String> {
    let bytes = read_bytes(path, kind)?;
    String::from_utf8(bytes).map_err(|error| {
        let at = error.utf8_error().valid_up_to();
        refused(format!(
            "not UTF-8 text (byte {at} of {}): {} is expected",
            error.as_bytes().len(),
            kind.name()
        ))
    })
}

/// Reads a JSON file (see [`read_bytes`]).
pub fn read_json_text(path: &Path) -> std::io::Result<String> {
    read_text(path, InputKind::Json)
}

fn too_large(bytes: u64, kind: InputKind) -> std::io::Error {
    let limit = kind.limit();
    let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
    refused(format!(
        "{}{:.1} MiB, more than the {:.0} MiB that {} may have",
        if bytes > limit { "over " } else { "" },
        mib(bytes.min(limit)),
        mib(limit),
        kind.name()
    ))
}

fn check_file_type(file_type: &std::fs::FileType, kind: InputKind) -> std::io::Result<()> {
    if file_type.is_file() {
        return Ok(());
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() && kind == InputKind::Csv {
            return Ok(());
        }
        let what = if file_type.is_dir() {
            "a directory"
        } else if file_type.is_fifo() {
            "a pipe (FIFO)"
        } else if file_type.is_char_device() {
            "a character device"
        } else if file_type.is_block_device() {
            "a block device"
        } else if file_type.is_socket() {
            "a socket"
        } else {
            "not a regular file"
        };
        Err(refused(format!("is {what}, not {}", kind.name())))
    }
    #[cfg(not(unix))]
    Err(refused(format!(
        "is not a regular file: {} is expected",
        kind.name()
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(unix)]
    fn devices_and_directories_are_refused_quickly() {
        let message = read_json_text(Path::new("/dev/zero"))
            .unwrap_err()
            .to_string();
        assert_eq!(message, "is a character device, not a JSON file");
        let message = read_bytes(Path::new("/dev/zero"), InputKind::Csv)
            .unwrap_err()
            .to_string();
        assert_eq!(message, "is a character device, not a CSV file");
        let message = read_json_text(Path::new("/")).unwrap_err().to_string();
        assert_eq!(message, "is a directory, not a JSON file");
        let message = read_json_text(Path::new("")).unwrap_err().to_string();
        assert_eq!(message, "an empty path names no file");
    }

    #[test]
    fn a_large_json_file_is_refused_before_it_is_read() {
        let file = tempfile::Builder::new()
            .prefix("data-large-")
            .suffix(".json")
            .tempfile()
            .unwrap();
        file.as_file().set_len(MAX_JSON_BYTES + 1).unwrap();
        let message = read_json_text(file.path()).unwrap_err().to_string();
        assert_eq!(
            message,
            "over 8.0 MiB, more than the 8 MiB that a JSON file may have"
        );
    }
}
