//! The framing of every message between the WebGPU backend and its page, whichever way
//! it travels (the loopback bridge natively, the worker's channel in a web page): a
//! little-endian `u32` with the length of a JSON header, the header, then raw bytes
//! (buffer and texture contents, WGSL) that the header points into as `[offset, length]`
//! pairs. `executor.js` reads and writes the same.

/// One message in the bridge's framing: a little-endian `u32` with the header's length,
/// the JSON header, the payload.
pub(super) fn frame(header: &serde_json::Value, payload: &[u8]) -> Vec<u8> {
    let json = header.to_string().into_bytes();
    let mut bytes = Vec::with_capacity(4 + json.len() + payload.len());
    bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&json);
    bytes.extend_from_slice(payload);
    bytes
}

/// A framed message's header and payload; the error says what is wrong with it.
pub(super) fn unframe(bytes: &[u8]) -> Result<(serde_json::Value, &[u8]), String> {
    let length = bytes.get(..4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let Some(length) = length.filter(|&n| n <= bytes.len() - 4) else {
        return Err(format!("a message of {} bytes has no whole header", bytes.len()));
    };
    let header = serde_json::from_slice(&bytes[4..4 + length]).map_err(|e| format!("its header is not JSON: {e}"))?;
    Ok((header, &bytes[4 + length..]))
}
