//! Reading a scene file's text, bounded: only a regular file is opened (a
//! FIFO would block the open forever, a device or `/dev/zero` would be read
//! without end), and only up to [`MAX_SCENE_BYTES`]. Every scene front-end
//! reads its text here.

use super::SceneError;
use std::io::Read;
use std::path::Path;

/// The largest scene file read. The text is parsed whole, and the parsed
/// tables with their spans take about 40 bytes of memory per byte of text
/// (a 9.2 MB file of 100,000 spheres peaks at 349 MB), so 100 MB (about a
/// million entries) needs about 4 GB. Larger geometry belongs in OBJ files
/// (`type = "mesh"`), which are streamed.
pub const MAX_SCENE_BYTES: u64 = 100_000_000;

/// The text of the scene file at `path`, or why it cannot be read: not a
/// regular file, larger than [`MAX_SCENE_BYTES`], unreadable, not UTF-8.
pub fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    let refuse =
        |message: String| SceneError { path: path.to_path_buf(), line: 0, column: 0, field: "(file)".into(), message };
    // The kind is asked without opening: opening a FIFO waits for a writer.
    let meta = std::fs::metadata(path).map_err(|e| refuse(format!("cannot read the scene file: {e}")))?;
    if !meta.is_file() {
        return Err(refuse(format!("cannot read the scene file: it is {}", kind(&meta))));
    }
    let too_large = |size: u64| {
        refuse(format!(
            "the scene file is {:.1} MB, more than the {} MB a scene file may be: it is parsed whole, at about 40 \
             bytes of memory per byte; put large geometry in OBJ files (type = \"mesh\"), which are streamed",
            size as f64 / 1e6,
            MAX_SCENE_BYTES / 1_000_000
        ))
    };
    if meta.len() > MAX_SCENE_BYTES {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| refuse(format!("cannot read the scene file: {e}")))?;
    // The file may have grown since its size was asked.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| refuse(format!("cannot read the scene file: {e}")))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| {
        refuse(format!("the scene file is not UTF-8 text (byte {} is not valid)", e.utf8_error().valid_up_to()))
    })
}

/// What a file that is not a regular one is, for the message.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe), not a regular file";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device, not a regular file";
        }
        if t.is_socket() {
            return "a socket, not a regular file";
        }
    }
    if meta.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_and_a_device_are_refused_with_what_they_are() {
        let dir = read_scene_text(Path::new(env!("CARGO_MANIFEST_DIR"))).unwrap_err();
        assert!(dir.message.contains("it is a directory"), "{dir}");
        #[cfg(unix)]
        {
            let zero = read_scene_text(Path::new("/dev/zero")).unwrap_err();
            assert!(zero.message.contains("a device, not a regular file"), "{zero}");
        }
    }

    #[test]
    fn a_file_over_the_cap_is_refused_unread_and_one_at_the_cap_is_read() {
        let dir = std::env::temp_dir().join(format!("photonmap-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("huge.toml");
        // Sparse: no disk space is used, and nothing is read.
        let file = std::fs::File::create(&path).unwrap();
        file.set_len(MAX_SCENE_BYTES + 1).unwrap();
        let e = read_scene_text(&path).unwrap_err();
        assert!(e.message.contains("100.0 MB, more than the 100 MB"), "{e}");
        file.set_len(MAX_SCENE_BYTES).unwrap();
        assert_eq!(read_scene_text(&path).unwrap().len() as u64, MAX_SCENE_BYTES);
        let bad = dir.join("latin1.toml");
        std::fs::write(&bad, b"# caf\xe9\n").unwrap();
        assert!(read_scene_text(&bad).unwrap_err().message.contains("byte 5 is not valid"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
