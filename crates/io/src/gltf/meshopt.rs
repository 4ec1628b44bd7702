//! `EXT_meshopt_compression`'s decoders, from the extension's specification (Appendix A and B of
//! its README in KhronosGroup/glTF): mode 0 (attributes, bitstream version 0), mode 1 (triangles,
//! version 1), mode 2 (indices, version 1), and the octahedral, quaternion and exponential
//! filters. Written here rather than through the `meshopt` crate, whose safe API lacks the
//! index-sequence mode and the filters (its raw bindings need `unsafe`, which rt denies) and
//! which would compile meshoptimizer's C++ into every build; the tests check these decoders
//! against that crate's encoders.
//!
//! Every read is bounds-checked: a damaged stream is an error, never a panic or a read past its
//! end.

type Result<T> = std::result::Result<T, String>;

/// A cursor over a compressed stream.
struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn byte(&mut self) -> Result<u8> {
        let b = *self.data.get(self.at).ok_or("the stream ends early")?;
        self.at += 1;
        Ok(b)
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.at)
    }

    /// An unsigned LEB128 value of at most 5 bytes.
    fn varint(&mut self) -> Result<u32> {
        let mut value = 0u32;
        for shift in (0..35).step_by(7) {
            let b = self.byte()?;
            value |= u32::from(b & 0x7f).checked_shl(shift).unwrap_or(0);
            if b < 0x80 {
                return Ok(value);
            }
        }
        Err("a varint longer than 5 bytes".into())
    }
}

fn unzigzag8(v: u8) -> u8 {
    (v >> 1) ^ (v & 1).wrapping_neg()
}

fn unzigzag32(v: u32) -> u32 {
    (v >> 1) ^ (v & 1).wrapping_neg()
}

/// Mode 0: `count` elements of `stride` bytes (a multiple of 4, at most 256).
pub fn decode_attributes(data: &[u8], count: usize, stride: usize) -> Result<Vec<u8>> {
    if stride == 0 || stride > 256 || !stride.is_multiple_of(4) {
        return Err(format!(
            "byteStride {stride} is not a multiple of 4 up to 256"
        ));
    }
    let tail = stride.max(32);
    if data.len() < 1 + tail {
        return Err("the stream is shorter than its header and tail".into());
    }
    if data[0] != 0xa0 {
        return Err(format!("attribute header 0x{:02x} is not 0xa0", data[0]));
    }
    let mut last: Vec<u8> = data[data.len() - stride..].to_vec();
    let body_end = data.len() - tail;
    let mut reader = Reader {
        data: &data[..body_end],
        at: 1,
    };
    let block_max = ((8192 / stride) & !15).min(256);
    let mut out = vec![0u8; count * stride];
    let mut deltas = [0u8; 256];
    let mut first = 0;
    while first < count {
        let block = block_max.min(count - first);
        let aligned = block.div_ceil(16) * 16;
        for k in 0..stride {
            decode_byte_column(&mut reader, &mut deltas[..aligned])?;
            let mut previous = last[k];
            for (i, &delta) in deltas[..block].iter().enumerate() {
                previous = previous.wrapping_add(unzigzag8(delta));
                out[(first + i) * stride + k] = previous;
            }
            last[k] = previous;
        }
        first += block;
    }
    if reader.at != body_end {
        return Err(format!(
            "{} bytes left over before the tail",
            body_end - reader.at
        ));
    }
    Ok(out)
}

/// One byte of every element of a block: 2-bit group headers, then each group of 16 deltas.
fn decode_byte_column(reader: &mut Reader, out: &mut [u8]) -> Result<()> {
    let groups = out.len() / 16;
    let header_bytes = groups.div_ceil(4);
    if reader.remaining() < header_bytes {
        return Err("the stream ends in a block header".into());
    }
    let header = &reader.data[reader.at..reader.at + header_bytes];
    reader.at += header_bytes;
    for (g, group) in out.chunks_exact_mut(16).enumerate() {
        let bits = (header[g / 4] >> ((g % 4) * 2)) & 3;
        match bits {
            0 => group.fill(0),
            3 => {
                for value in group.iter_mut() {
                    *value = reader.byte()?;
                }
            }
            _ => {
                let width = if bits == 1 { 2 } else { 4 };
                let packed_bytes = 16 * width / 8;
                if reader.remaining() < packed_bytes {
                    return Err("the stream ends in a group".into());
                }
                let packed = &reader.data[reader.at..reader.at + packed_bytes];
                reader.at += packed_bytes;
                let sentinel = (1u8 << width) - 1;
                for (i, value) in group.iter_mut().enumerate() {
                    let bit = i * width;
                    let code = (packed[bit / 8] >> (8 - width - bit % 8)) & sentinel;
                    *value = if code == sentinel {
                        reader.byte()?
                    } else {
                        code
                    };
                }
            }
        }
    }
    Ok(())
}

/// Mode 1: a triangle list of `count` indices (a multiple of 3).
pub fn decode_triangles(data: &[u8], count: usize) -> Result<Vec<u32>> {
    if !count.is_multiple_of(3) {
        return Err(format!("{count} indices are no whole triangles"));
    }
    let triangles = count / 3;
    if data.len() < 1 + triangles + 16 {
        return Err("the stream is shorter than its codes and table".into());
    }
    if data[0] != 0xe1 {
        return Err(format!("triangle header 0x{:02x} is not 0xe1", data[0]));
    }
    let codes = &data[1..1 + triangles];
    let table = &data[data.len() - 16..];
    let mut reader = Reader {
        data: &data[..data.len() - 16],
        at: 1 + triangles,
    };
    let mut edges = [[u32::MAX; 2]; 16];
    let mut vertices = [u32::MAX; 16];
    let (mut edge_at, mut vertex_at) = (0usize, 0usize);
    let (mut next, mut last) = (0u32, 0u32);
    let mut out = Vec::with_capacity(count);
    let index = |reader: &mut Reader, last: &mut u32| -> Result<u32> {
        *last = last.wrapping_add(unzigzag32(reader.varint()?));
        Ok(*last)
    };
    for &code in codes {
        let recent_vertex = |vertices: &[u32; 16], vertex_at: usize, back: usize| {
            vertices[(vertex_at + 16 - back) & 15]
        };
        let (a, b, c);
        let mut push_vertices: [(u32, bool); 3] = [(0, false); 3];
        if code < 0xf0 {
            let edge = edges[(edge_at + 15 - usize::from(code >> 4)) & 15];
            (a, b) = (edge[0], edge[1]);
            let low = code & 15;
            c = match low {
                0 => {
                    next = next.wrapping_add(1);
                    next.wrapping_sub(1)
                }
                1..=12 => recent_vertex(&vertices, vertex_at, usize::from(low) + 1),
                13 | 14 => {
                    last = if low == 13 {
                        last.wrapping_sub(1)
                    } else {
                        last.wrapping_add(1)
                    };
                    last
                }
                _ => index(&mut reader, &mut last)?,
            };
            push_vertices[0] = (c, low == 0 || low >= 13);
            out.extend([a, b, c]);
            for (x, y) in [(c, b), (a, c)] {
                edges[edge_at] = [x, y];
                edge_at = (edge_at + 1) & 15;
            }
        } else {
            let (explicit, aux) = if code < 0xfe {
                (false, table[usize::from(code & 15)])
            } else {
                let aux = reader.byte()?;
                if aux == 0 {
                    next = 0;
                }
                (code == 0xff, aux)
            };
            let (zb, zc) = (usize::from(aux >> 4), usize::from(aux & 15));
            let mut take_next = || {
                next = next.wrapping_add(1);
                next.wrapping_sub(1)
            };
            let mut first = if explicit { 0 } else { take_next() };
            let mut second = if zb == 0 {
                take_next()
            } else {
                recent_vertex(&vertices, vertex_at, zb)
            };
            let mut third = if zc == 0 {
                take_next()
            } else {
                recent_vertex(&vertices, vertex_at, zc)
            };
            if code >= 0xfe {
                if explicit {
                    first = index(&mut reader, &mut last)?;
                }
                if zb == 15 {
                    second = index(&mut reader, &mut last)?;
                }
                if zc == 15 {
                    third = index(&mut reader, &mut last)?;
                }
            }
            (a, b, c) = (first, second, third);
            let fresh = |z: usize| z == 0 || (code >= 0xfe && z == 15);
            push_vertices = [(a, true), (b, fresh(zb)), (c, fresh(zc))];
            out.extend([a, b, c]);
            for (x, y) in [(b, a), (c, b), (a, c)] {
                edges[edge_at] = [x, y];
                edge_at = (edge_at + 1) & 15;
            }
        }
        for (v, push) in push_vertices {
            vertices[vertex_at] = v;
            vertex_at = (vertex_at + usize::from(push)) & 15;
        }
    }
    if reader.at != reader.data.len() {
        return Err("extra data after the last triangle".into());
    }
    Ok(out)
}

/// Mode 2: `count` indices, each a delta from one of two baselines.
pub fn decode_indices(data: &[u8], count: usize) -> Result<Vec<u32>> {
    if data.len() < 1 + count + 4 {
        return Err("the stream is shorter than its indices and tail".into());
    }
    if data[0] != 0xd1 {
        return Err(format!("index header 0x{:02x} is not 0xd1", data[0]));
    }
    let mut reader = Reader {
        data: &data[..data.len() - 4],
        at: 1,
    };
    let mut last = [0u32; 2];
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let v = reader.varint()?;
        let baseline = (v & 1) as usize;
        last[baseline] = last[baseline].wrapping_add(unzigzag32(v >> 1));
        out.push(last[baseline]);
    }
    if reader.at != reader.data.len() {
        return Err("extra data after the last index".into());
    }
    Ok(out)
}

/// The octahedral filter over decoded elements of 4 (8-bit) or 8 (16-bit) bytes, in place.
pub fn filter_octahedral(bytes: &mut [u8], stride: usize) -> Result<()> {
    let decode = |input: [f32; 4], max: f32| {
        let one = input[2];
        let (mut x, mut y) = (input[0] / one, input[1] / one);
        let z = 1.0 - x.abs() - y.abs();
        let t = z.min(0.0);
        x -= t.copysign(x);
        y -= t.copysign(y);
        let length = (x * x + y * y + z * z).sqrt();
        [x, y, z].map(|c| (c / length * max).round())
    };
    match stride {
        4 => {
            for e in bytes.chunks_exact_mut(4) {
                let input = [e[0], e[1], e[2], e[3]].map(|b| f32::from(b as i8));
                let [x, y, z] = decode(input, 127.0);
                (e[0], e[1], e[2]) = (x as i8 as u8, y as i8 as u8, z as i8 as u8);
            }
        }
        8 => {
            for e in bytes.chunks_exact_mut(8) {
                let input: [f32; 4] = std::array::from_fn(|i| {
                    f32::from(i16::from_le_bytes([e[2 * i], e[2 * i + 1]]))
                });
                let decoded = decode(input, 32767.0);
                for (i, v) in decoded.into_iter().enumerate() {
                    e[2 * i..2 * i + 2].copy_from_slice(&(v as i16).to_le_bytes());
                }
            }
        }
        _ => {
            return Err(format!(
                "the octahedral filter needs byteStride 4 or 8, not {stride}"
            ));
        }
    }
    Ok(())
}

/// The quaternion filter over decoded 8-byte elements, in place.
pub fn filter_quaternion(bytes: &mut [u8], stride: usize) -> Result<()> {
    if stride != 8 {
        return Err(format!(
            "the quaternion filter needs byteStride 8, not {stride}"
        ));
    }
    let range = std::f32::consts::FRAC_1_SQRT_2;
    for e in bytes.chunks_exact_mut(8) {
        let input: [i16; 4] = std::array::from_fn(|i| i16::from_le_bytes([e[2 * i], e[2 * i + 1]]));
        let one = f32::from(input[3] | 3);
        let [x, y, z] = [0, 1, 2].map(|i| f32::from(input[i]) / one * range);
        let w = (1.0 - x * x - y * y - z * z).max(0.0).sqrt();
        let largest = (input[3] & 3) as usize;
        let mut output = [0i16; 4];
        for (offset, value) in [(1, x), (2, y), (3, z), (0, w)] {
            output[(largest + offset) % 4] = (value * 32767.0).round() as i16;
        }
        for (i, v) in output.into_iter().enumerate() {
            e[2 * i..2 * i + 2].copy_from_slice(&v.to_le_bytes());
        }
    }
    Ok(())
}

/// The exponential filter over decoded 32-bit values, in place: 2^e · m.
pub fn filter_exponential(bytes: &mut [u8], stride: usize) -> Result<()> {
    if !stride.is_multiple_of(4) {
        return Err(format!(
            "the exponential filter needs a byteStride multiple of 4, not {stride}"
        ));
    }
    for v in bytes.chunks_exact_mut(4) {
        let input = i32::from_le_bytes([v[0], v[1], v[2], v[3]]);
        let (e, m) = (input >> 24, (input << 8) >> 8);
        let value = (m as f32) * 2f32.powi(e);
        v.copy_from_slice(&value.to_le_bytes());
    }
    Ok(())
}
