//! Byte- and text-level mutations shared by every target: bit flips, byte sets, inserts,
//! deletes, duplications, splices between corpus inputs, little-endian integer and float
//! fields set to edge values, and decimal numbers in text replaced by edge values (`NaN`,
//! `1e39`, `-1`, `4294967296`, ...). Each takes the generator, so a campaign is
//! deterministic from its seed.

use rand::Rng;
use rand_pcg::Pcg64Mcg;

/// The campaign's random generator.
pub type FuzzRng = Pcg64Mcg;

/// Decimal texts that break loaders: non-finite, beyond f32, negative, beyond u32/u64,
/// tiny, zero.
pub const EDGE_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "255",
    "256",
    "65535",
    "65536",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1e39",
    "-1e39",
    "1e308",
    "1e309",
    "-1e309",
    "3.4028236e38",
    "1e-45",
    "1e-50",
    "0.5",
    "2147483647",
    "2147483648",
    "-2147483648",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775809",
    "99999999999999999999999",
    "1.5",
    "0x10",
    "",
];

/// Little-endian 32-bit words that break binary readers.
const EDGE_U32: &[u32] = &[
    0,
    1,
    2,
    3,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_fffe,
    0xffff_ffff,
    0x7f80_0000, // +Inf as f32
    0xff80_0000, // -Inf
    0x7fc0_0000, // NaN
    0xbf80_0000, // -1.0
    0x0000_0001, // denormal
    0x7f7f_ffff, // f32::MAX
];

/// One random byte-level mutation of `input` (`other` is another corpus input to splice
/// with).
pub fn mutate_bytes(rng: &mut FuzzRng, input: &mut Vec<u8>, other: &[u8]) {
    let len = input.len();
    match rng.random_range(0..12) {
        0 if len > 0 => {
            let i = rng.random_range(0..len);
            input[i] ^= 1 << rng.random_range(0..8);
        }
        1 if len > 0 => {
            let i = rng.random_range(0..len);
            input[i] = *[0u8, 0xff, 0x7f, 0x80, b'0', b'9', b'-', b'.', b'\n', b' ', b'"', b',']
                .get(rng.random_range(0..12))
                .unwrap_or(&0);
        }
        2 if len > 0 => {
            let i = rng.random_range(0..len);
            input[i] = rng.random();
        }
        3 => {
            let at = rng.random_range(0..=len);
            let count = 1 + rng.random_range(0..16);
            let fill: Vec<u8> = (0..count).map(|_| rng.random()).collect();
            input.splice(at..at, fill);
        }
        4 if len > 0 => {
            let at = rng.random_range(0..len);
            let count = 1 + rng.random_range(0..(len - at).min(64));
            input.drain(at..at + count);
        }
        5 if len > 0 => {
            // Duplicate a range (repeated elements, lines, chunks).
            let at = rng.random_range(0..len);
            let count = 1 + rng.random_range(0..(len - at).min(256));
            let copy = input[at..at + count].to_vec();
            let to = rng.random_range(0..=len);
            input.splice(to..to, copy);
        }
        6 if !other.is_empty() => {
            // Splice: a prefix of this input and a suffix of another.
            let cut = rng.random_range(0..=len);
            let from = rng.random_range(0..other.len());
            input.truncate(cut);
            input.extend_from_slice(&other[from..]);
        }
        7 | 8 if len >= 4 => {
            let i = rng.random_range(0..=len - 4);
            let word = EDGE_U32[rng.random_range(0..EDGE_U32.len())];
            input[i..i + 4].copy_from_slice(&word.to_le_bytes());
        }
        9 if len >= 2 => {
            let i = rng.random_range(0..=len - 2);
            let word: u16 = *[0u16, 1, 0x7fff, 0x8000, 0xffff].get(rng.random_range(0..5)).unwrap_or(&0);
            input[i..i + 2].copy_from_slice(&word.to_le_bytes());
        }
        10 if len > 0 => {
            // Truncate.
            input.truncate(rng.random_range(0..len));
        }
        _ => mutate_number_text(rng, input),
    }
}

/// Replaces one decimal number of the text in `input` (found by scanning from a random
/// place) with an edge value, or nudges it; nothing happens if there is no number.
pub fn mutate_number_text(rng: &mut FuzzRng, input: &mut Vec<u8>) {
    let spans = number_spans(input);
    if spans.is_empty() {
        return;
    }
    let (start, end) = spans[rng.random_range(0..spans.len())];
    let replacement = number_replacement(rng, &input[start..end]);
    input.splice(start..end, replacement.into_bytes());
}

/// A replacement for the decimal number `old`: an edge value, or the number changed.
pub fn number_replacement(rng: &mut FuzzRng, old: &[u8]) -> String {
    let value: Option<f64> = std::str::from_utf8(old).ok().and_then(|t| t.parse().ok());
    match (rng.random_range(0..4), value) {
        (0, Some(v)) => format!("{}", v + if rng.random() { 1.0 } else { -1.0 }),
        (1, Some(v)) => format!("{}", -v),
        (2, Some(v)) => format!("{}", v * 1e20),
        _ => EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())].to_string(),
    }
}

/// Byte ranges of the decimal numbers (optional sign, digits, fraction, exponent) in `text`.
pub fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let start = i;
        if text[i] == b'-' || text[i] == b'+' {
            i += 1;
        }
        let digits_start = i;
        while i < text.len() && (text[i].is_ascii_digit() || text[i] == b'.') {
            i += 1;
        }
        if i > digits_start && text[digits_start..i].iter().any(u8::is_ascii_digit) {
            if i < text.len() && (text[i] == b'e' || text[i] == b'E') {
                let mut j = i + 1;
                if j < text.len() && (text[j] == b'-' || text[j] == b'+') {
                    j += 1;
                }
                let exponent = j;
                while j < text.len() && text[j].is_ascii_digit() {
                    j += 1;
                }
                if j > exponent {
                    i = j;
                }
            }
            // Only numbers that stand alone (not inside a name like `obj_00`).
            let before = start.checked_sub(1).map(|b| text[b]);
            if !before.is_some_and(|b| b.is_ascii_alphabetic() || b == b'_') {
                spans.push((start, i));
            }
        } else {
            i = start + 1;
        }
    }
    spans
}

/// Byte ranges of the lines of `text` (without their `\n`).
pub fn line_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i));
            start = i + 1;
        }
    }
    if start < text.len() {
        spans.push((start, text.len()));
    }
    spans
}

/// One random line-level mutation of a text input: a line dropped, duplicated, swapped
/// with another, or one of its numbers replaced.
pub fn mutate_lines(rng: &mut FuzzRng, input: &mut Vec<u8>) {
    let lines = line_spans(input);
    if lines.is_empty() {
        return;
    }
    let (start, end) = lines[rng.random_range(0..lines.len())];
    match rng.random_range(0..4) {
        0 => {
            input.drain(start..(end + 1).min(input.len()));
        }
        1 => {
            let mut copy = input[start..end].to_vec();
            copy.push(b'\n');
            input.splice(start..start, copy);
        }
        2 => {
            let (other_start, other_end) = lines[rng.random_range(0..lines.len())];
            let copy = input[other_start..other_end].to_vec();
            input.splice(start..end, copy);
        }
        _ => {
            let mut line = input[start..end].to_vec();
            mutate_number_text(rng, &mut line);
            input.splice(start..end, line);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn numbers_are_found_alone_not_inside_names() {
        let text = b"v 1.5 -2e-3 +4\nobj_00 x7 [0,1]";
        let found: Vec<&[u8]> = number_spans(text).into_iter().map(|(a, b)| &text[a..b]).collect();
        assert_eq!(found, vec![&b"1.5"[..], b"-2e-3", b"+4", b"0", b"1"]);
    }

    #[test]
    fn mutations_are_deterministic_from_the_seed() {
        let run = |seed| {
            let mut rng = FuzzRng::seed_from_u64(seed);
            let mut input = b"ply\nelement vertex 3\n0 1 2\n".to_vec();
            for _ in 0..50 {
                mutate_bytes(&mut rng, &mut input, b"other 12");
            }
            input
        };
        assert_eq!(run(7), run(7));
        assert_ne!(run(7), run(8));
    }
}
