//! OBJ and MTL text as tobj needs it: decoded forgivingly, checked where tobj is silent or would
//! panic, with line numbers kept.

use std::borrow::Cow;
use std::path::Path;

use rt_core::error::{Error, Result};

/// Checks what tobj accepts silently or reports without a line: vertex coordinates that are not
/// finite numbers, faces with fewer than 3 vertices, and indices that are zero or out of range.
pub fn validate_obj_text(path: &Path, text: &str) -> Result<()> {
    let (mut positions, mut uvs, mut normals) = (0i64, 0i64, 0i64);
    for (line_index, raw) in text.lines().enumerate() {
        let fail = |message: String| Error::Parse {
            path: path.into(),
            line: line_index + 1,
            message,
        };
        let mut words = raw.split_whitespace();
        let keyword = words.next().unwrap_or("");
        match keyword {
            "v" | "vn" | "vt" => {
                let needed = if keyword == "vt" { 1 } else { 3 };
                let mut count = 0;
                for word in words.by_ref().take(if keyword == "v" { 3 } else { needed }) {
                    let value: f32 = word
                        .parse()
                        .map_err(|_| fail(format!("'{word}' is not a number")))?;
                    if !value.is_finite() {
                        return Err(fail(format!("coordinate '{word}' is not finite")));
                    }
                    count += 1;
                }
                if count < needed {
                    return Err(fail(format!(
                        "'{keyword}' needs {needed} coordinates, found {count}"
                    )));
                }
                match keyword {
                    "v" => positions += 1,
                    "vt" => uvs += 1,
                    _ => normals += 1,
                }
            }
            "f" => {
                let mut corners = 0;
                for word in words {
                    corners += 1;
                    for (slot, part) in word.split('/').enumerate() {
                        if part.is_empty() && slot > 0 {
                            continue;
                        }
                        let (kind, count) = match slot {
                            0 => ("vertex", positions),
                            1 => ("texture coordinate", uvs),
                            2 => ("normal", normals),
                            _ => {
                                return Err(fail(format!("face corner '{word}' has too many '/'")));
                            }
                        };
                        let index: i64 = part
                            .parse()
                            .map_err(|_| fail(format!("'{part}' is not an index")))?;
                        let valid = (index > 0 && index <= count) || (index < 0 && -index <= count);
                        if !valid {
                            return Err(fail(format!(
                                "{kind} index {index} is out of range (1..={count} or -{count}..=-1)"
                            )));
                        }
                    }
                }
                if corners < 3 {
                    return Err(fail(format!(
                        "a face needs at least 3 vertices, found {corners}"
                    )));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The file as text, forgiving as Blender and assimp are: UTF-8 (a byte-order mark skipped);
/// UTF-16 with its byte-order mark; otherwise each byte as its Latin-1 character, with a warning
/// naming the first line that is not UTF-8 (material and object names from old Windows tools).
/// A file with NUL or many other control bytes is binary: an error naming the line.
pub fn decode_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<Cow<'a, str>> {
    let line_at = |offset: usize| bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
    if let Some(utf16) = utf16_text(bytes) {
        return Ok(Cow::Owned(utf16));
    }
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let control = |b: &u8| *b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r' | 0x0c);
    if let Some(nul) = bytes.iter().position(|&b| b == 0).or_else(|| {
        (bytes.iter().filter(|b| control(b)).count() * 100 > bytes.len())
            .then(|| bytes.iter().position(control).unwrap_or(0))
    }) {
        return Err(Error::Parse {
            path: path.into(),
            line: line_at(nul),
            message: "not text (a binary file?)".into(),
        });
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(Cow::Borrowed(text)),
        Err(e) => {
            log::warn!(
                "{}:{}: not UTF-8; the file is read as Latin-1",
                path.display(),
                line_at(e.valid_up_to())
            );
            Ok(Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()))
        }
    }
}

/// UTF-16 text with a byte-order mark (either endianness), decoded; `None` without the mark.
fn utf16_text(bytes: &[u8]) -> Option<String> {
    let (big_endian, body) = match bytes {
        [0xFE, 0xFF, rest @ ..] => (true, rest),
        [0xFF, 0xFE, rest @ ..] => (false, rest),
        _ => return None,
    };
    let units = body.chunks_exact(2).map(|pair| {
        let pair = [pair[0], pair[1]];
        if big_endian {
            u16::from_be_bytes(pair)
        } else {
            u16::from_le_bytes(pair)
        }
    });
    Some(
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect(),
    )
}

/// The name rt gives a material declared or used without one (`newmtl` or `usemtl` alone on its
/// line, as Blender writes a material with an empty name); tobj refuses an empty name.
pub const UNNAMED_MATERIAL: &str = "unnamed";

/// `text` with every `keyword` (`newmtl` or `usemtl`) that has no name given [`UNNAMED_MATERIAL`],
/// line numbers kept.
pub fn name_unnamed_materials<'a>(text: &'a str, keyword: &str) -> Cow<'a, str> {
    let unnamed = |line: &str| line.split_whitespace().eq([keyword]);
    if !text.lines().any(unnamed) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    for line in text.lines() {
        if unnamed(line) {
            out.push_str(&format!("{keyword} {UNNAMED_MATERIAL}"));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    Cow::Owned(out)
}

/// Colour statements (`Ka`, `Kd`, `Ks`, `Ke`) checked and written with three values: the MTL format
/// lets g and b be omitted (`Kd 0.5` is grey), which tobj 4 does not accept (it panics), and
/// non-numbers or a missing blue get an error naming the line. Line numbers are kept.
pub fn normalize_mtl_colors(path: &Path, text: &str) -> Result<String> {
    let mut out = String::with_capacity(text.len() + 64);
    for (index, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        if matches!(keyword, "Ka" | "Kd" | "Ks" | "Ke") {
            let fail = |message: String| Error::Parse {
                path: path.into(),
                line: index + 1,
                message,
            };
            let values = words
                .map(|w| match w.parse::<f32>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(fail(format!("'{w}' in '{keyword}' is not a finite number (spectral and xyz colours are not supported)"))),
                })
                .collect::<Result<Vec<f32>>>()?;
            let rgb = match values.as_slice() {
                [g] => [*g; 3],
                [r, g, b, ..] => [*r, *g, *b],
                _ => {
                    return Err(fail(format!(
                        "'{keyword}' needs 1 or 3 numbers, found {}",
                        values.len()
                    )));
                }
            };
            out.push_str(&format!("{keyword} {} {} {}\n", rgb[0], rgb[1], rgb[2]));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(out)
}
