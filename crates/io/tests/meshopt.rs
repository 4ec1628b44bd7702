//! `EXT_meshopt_compression`'s decoders against meshoptimizer's own encoders (the `meshopt` crate,
//! C++): attributes of every stride class and block boundary, triangle lists; the index mode and
//! the filters against the specification's formulas; damaged streams are errors, never panics.

#![expect(clippy::unwrap_used, reason = "test helpers fail by panicking")]

use rt_core::math::rng::pcg_hash;
use rt_io::gltf::meshopt::{
    decode_attributes, decode_indices, decode_triangles, filter_exponential, filter_octahedral,
    filter_quaternion,
};

/// Elements whose bytes vary smoothly (small deltas), jump (large ones) and stay put (zero
/// deltas), so that every group encoding occurs.
fn elements<const N: usize>(count: usize, seed: u32) -> Vec<[u8; N]> {
    (0..count)
        .map(|i| {
            std::array::from_fn(|k| match k % 4 {
                0 => (i / 3) as u8,
                1 => pcg_hash(seed ^ (i * N + k) as u32) as u8,
                2 => 7,
                _ => (i as u8).wrapping_mul(13),
            })
        })
        .collect()
}

fn round_trip<const N: usize>() {
    for count in [1usize, 2, 15, 16, 17, 31, 255, 256, 257, 1000, 5003] {
        let data = elements::<N>(count, count as u32);
        let encoded = meshopt::encode_vertex_buffer(&data).unwrap();
        let decoded =
            decode_attributes(&encoded, count, N).unwrap_or_else(|e| panic!("{N}×{count}: {e}"));
        assert_eq!(decoded, data.concat(), "stride {N}, {count} elements");
    }
}

#[test]
fn attributes_decode_as_meshoptimizer_encodes_them() {
    round_trip::<4>();
    round_trip::<8>();
    round_trip::<12>();
    round_trip::<16>();
    round_trip::<20>();
    round_trip::<64>();
    round_trip::<256>();
}

/// Triangle lists decode to the triangles encoded, each with its winding (meshoptimizer may start
/// a triangle at another corner).
/// Triangle lists decode to the triangles encoded, each with its winding (meshoptimizer may start
/// a triangle at another corner).
#[test]
fn triangles_decode_as_meshoptimizer_encodes_them() {
    // A grid (shared edges, the codec's common case) and random triangles (explicit indices).
    let side = 40u32;
    let mut grid = Vec::new();
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let v = y * side + x;
            grid.extend([v, v + 1, v + side, v + 1, v + side + 1, v + side]);
        }
    }
    let random: Vec<u32> = (0..3000u32).map(|i| pcg_hash(i) % 70_000).collect();
    let small = vec![0u32, 1, 2];
    for (what, indices, vertices) in [
        ("grid", grid, (side * side) as usize),
        ("random", random, 70_000),
        ("one triangle", small, 3),
    ] {
        let encoded = meshopt::encode_index_buffer(&indices, vertices).unwrap();
        assert_eq!(
            encoded[0], 0xe1,
            "{what}: version 1, as the extension requires"
        );
        let decoded =
            decode_triangles(&encoded, indices.len()).unwrap_or_else(|e| panic!("{what}: {e}"));
        // The encoder may rotate a triangle's corners (never its winding).
        let turned = |t: &[u32]| {
            let first = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
            [t[first], t[(first + 1) % 3], t[(first + 2) % 3]]
        };
        let same = decoded.len() == indices.len()
            && decoded
                .chunks(3)
                .zip(indices.chunks(3))
                .all(|(a, b)| turned(a) == turned(b));
        assert!(same, "{what}: the triangles differ");
    }
}

/// The index mode's bitstream written from the specification: a varint per index, its low bit
/// the baseline and the rest the zigzag delta from it.
fn encode_indices(indices: &[u32]) -> Vec<u8> {
    let mut out = vec![0xd1];
    let mut last = [0u32; 2];
    for (i, &index) in indices.iter().enumerate() {
        let baseline = i % 2;
        let delta = index.wrapping_sub(last[baseline]) as i32;
        last[baseline] = index;
        let mut v = (((delta << 1) ^ (delta >> 31)) as u32) << 1 | baseline as u32;
        while v >= 0x80 {
            out.push((v as u8) | 0x80);
            v >>= 7;
        }
        out.push(v as u8);
    }
    out.extend([0; 4]);
    out
}

#[test]
fn indices_decode_as_the_specification_writes_them() {
    let strip: Vec<u32> = (0..500u32)
        .map(|i| if i % 2 == 0 { i / 2 } else { 1000 + i })
        .collect();
    let far = vec![0u32, 1 << 28, 3, (1 << 30) - 1, 2];
    for indices in [strip, far, vec![0]] {
        assert_eq!(
            decode_indices(&encode_indices(&indices), indices.len()).unwrap(),
            indices
        );
    }
}

#[test]
fn filters_decode_as_the_specification_says() {
    // Octahedral, 8 bits: +Z is (0, 0, 1); a vector in the lower hemisphere folds back.
    let mut bytes = vec![0u8, 0, 127, 9];
    filter_octahedral(&mut bytes, 4).unwrap();
    assert_eq!(bytes, [0, 0, 127, 9], "+Z, the fourth byte passed through");
    // 16 bits, K = 12 (one = 2047): (x, y) = (0.5, 0.5) is the equator's (0.5, 0.5, 0) direction.
    let mut bytes: Vec<u8> = [1023i16, 1023, 2047, -5]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    filter_octahedral(&mut bytes, 8).unwrap();
    let out: Vec<i16> = bytes
        .chunks(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect();
    let expected = (1023.0f32 / 2047.0 / (2.0f32 * (1023.0 / 2047.0f32).powi(2)).sqrt() * 32767.0)
        .round() as i16;
    assert!(
        (out[0] - expected).abs() <= 1 && out[0] == out[1],
        "{out:?}"
    );
    assert!(out[2].abs() <= 40 && out[3] == -5, "{out:?}");
    // (0, 0, -1): x = y = 0 with the third component's sign: octahedral (1, 1) folds to -Z.
    let mut bytes = vec![127u8, 127, 127, 0];
    filter_octahedral(&mut bytes, 4).unwrap();
    assert_eq!(bytes[..3], [0, 0, (-127i8) as u8]);

    // Quaternion: the identity (w largest, index 3), K = 16: the three others 0.
    let mut bytes: Vec<u8> = [0i16, 0, 0, 32767 & !3 | 3]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    filter_quaternion(&mut bytes, 8).unwrap();
    let out: Vec<i16> = bytes
        .chunks(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect();
    assert_eq!(out, [0, 0, 0, 32767]);

    // Exponential: 2^-3 · 5 and 2^4 · -7.
    let mut bytes: Vec<u8> = [(-3i32 << 24) | 5, (4 << 24) | (-7i32 & 0x00ff_ffff)]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    filter_exponential(&mut bytes, 4).unwrap();
    let out: Vec<f32> = bytes
        .chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(out, [0.625, -112.0]);
}

#[test]
fn damaged_streams_are_errors_never_panics() {
    let data = elements::<12>(300, 1);
    let attributes = meshopt::encode_vertex_buffer(&data).unwrap();
    let grid: Vec<u32> = (0..600u32).map(|i| i / 2).collect();
    let triangles = meshopt::encode_index_buffer(&grid, 300).unwrap();
    let indices = encode_indices(&grid);
    let mut errors = 0;
    for i in 0..10_000u32 {
        let (seed, count): (&[u8], usize) = match i % 3 {
            0 => (&attributes, 300),
            1 => (&triangles, 600),
            _ => (&indices, 600),
        };
        let mut stream = seed.to_vec();
        match pcg_hash(i) % 3 {
            0 => {
                let at = pcg_hash(i ^ 1) as usize % stream.len();
                stream[at] = pcg_hash(i ^ 2) as u8;
            }
            1 => stream.truncate(pcg_hash(i ^ 3) as usize % stream.len()),
            _ => stream.insert(pcg_hash(i ^ 4) as usize % stream.len(), pcg_hash(i) as u8),
        }
        let result = std::panic::catch_unwind(|| match i % 3 {
            0 => decode_attributes(&stream, count, 12).map(|_| ()),
            1 => decode_triangles(&stream, count).map(|_| ()),
            _ => decode_indices(&stream, count).map(|_| ()),
        });
        errors += usize::from(result.expect("a decoder panicked").is_err());
    }
    assert!(errors > 3000, "{errors} of 10,000 damaged streams refused");
}
