//! The URIs a glTF file names its buffers and images by: `data:` URIs with base64
//! contents, decoded here, and relative (percent-encoded) or `file:` paths, turned into
//! paths for the loader's [`super::FileSource`]. Other schemes are refused.

use std::path::{Path, PathBuf};

/// Where a URI's bytes are.
#[derive(Debug, PartialEq)]
pub(super) enum Resolved {
    /// The bytes of a `data:` URI.
    Data(Vec<u8>),
    /// A file, joined to the glTF file's folder.
    File(PathBuf),
}

/// Resolves `uri` against `folder`; an error says what is wrong with it.
pub(super) fn resolve(uri: &str, folder: &Path) -> Result<Resolved, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) =
            rest.split_once(";base64,").ok_or("a `data:` URI without `;base64,` contents is not supported")?;
        return base64(payload).map(Resolved::Data);
    }
    if let Some(rest) = uri.strip_prefix("file://").or_else(|| uri.strip_prefix("file:")) {
        return Ok(Resolved::File(folder.join(percent_decoded(rest)?)));
    }
    if uri.contains(':') {
        return Err(format!("`{uri}`: unsupported URI scheme"));
    }
    Ok(Resolved::File(folder.join(percent_decoded(uri)?)))
}

/// `text` with `%XX` escapes decoded; the result must be UTF-8.
fn percent_decoded(text: &str) -> Result<String, String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
            let value = hex
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("`{text}`: `%` at byte {i} is not followed by two hexadecimal digits"))?;
            out.push(value);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("`{text}`: the decoded path is not UTF-8"))
}

/// Standard base64 (padding optional, whitespace refused).
fn base64(text: &str) -> Result<Vec<u8>, String> {
    let digits = text.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(digits.len() / 4 * 3 + 3);
    let mut accumulator = 0u32;
    let mut bits = 0;
    for (index, &c) in digits.iter().enumerate() {
        let value = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return Err(format!("base64 data: byte {index} (`{}`) is not a base64 digit", c.escape_ascii())),
        };
        accumulator = (accumulator << 6) | u32::from(value);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((accumulator >> bits) as u8);
            accumulator &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("base64 data: the length is not possible (one digit too many)".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_decode_and_paths_join() {
        let folder = Path::new("/scenes");
        assert_eq!(
            resolve("data:application/octet-stream;base64,AAEC/w==", folder),
            Ok(Resolved::Data(vec![0, 1, 2, 255]))
        );
        assert_eq!(resolve("data:;base64,TWFu", folder), Ok(Resolved::Data(b"Man".to_vec())));
        assert_eq!(resolve("a%20b.bin", folder), Ok(Resolved::File("/scenes/a b.bin".into())));
        assert!(resolve("a%ZZ.bin", folder).unwrap_err().contains("hexadecimal"));
        assert!(resolve("a%FF.bin", folder).unwrap_err().contains("UTF-8"));
        assert!(resolve("https://example.com/a.bin", folder).unwrap_err().contains("scheme"));
        assert!(resolve("data:;base64,A", folder).is_err());
        assert!(resolve("data:;base64,A*B", folder).is_err());
    }
}
