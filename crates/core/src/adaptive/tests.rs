use super::*;

/// Pixels whose samples are rare bright values on a dim floor (a caustic): 0.5, or 40 with
/// probability 3%, grey (luminance = value). Expectation 1.685.
struct Caustic(u64);

const DIM: f64 = 0.5;
const BRIGHT: f64 = 40.0;
const P_BRIGHT: f64 = 0.03;
const EXPECTED: f64 = (1.0 - P_BRIGHT) * DIM + P_BRIGHT * BRIGHT;

impl Caustic {
    fn sample(&mut self) -> [f64; 4] {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let u = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
        let v = if u < P_BRIGHT { BRIGHT } else { DIM };
        [v, v, v, v * v]
    }
}

/// Renders `images` images of `side`² such pixels adaptively, batches of 8 samples (4 to each
/// stream), at most `max` samples; returns the streams of each.
fn render(images: u64, side: usize, max: u32, rule: Adaptive) -> Vec<AdaptiveStreams> {
    (0..images)
        .map(|seed| {
            let mut rng = Caustic(seed * 7919 + 1);
            let mut streams = AdaptiveStreams::new(rule, side, side * side);
            while streams.active() > 0 && streams.dealt[0] + streams.dealt[1] < max {
                let batches: Vec<[[f64; 4]; 2]> = (0..side * side)
                    .map(|_| {
                        let mut add = [[0.0; 4]; 2];
                        for k in 0..8 {
                            let v = rng.sample();
                            for c in 0..4 {
                                add[k % 2][c] += v[c];
                            }
                        }
                        add
                    })
                    .collect();
                streams.add([4, 4], |i| batches[i]);
                streams.settle();
            }
            streams
        })
        .collect()
}

/// z of the mean of `values` against `expected`, with the standard error from their spread.
fn z_score(values: &[f64], expected: f64) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean - expected) / (variance / n).sqrt()
}

/// The image keeps the pixels' expectation where rare bright samples decide it: a Z-test of
/// the mean over 32,768 adaptively sampled pixels, of which many stop early. The same renders
/// valued by each pixel's own samples at its stop (the rule deciding on the samples it keeps)
/// fail the same test: the test can tell.
#[test]
fn two_streams_keep_the_expectation_where_rare_bright_samples_decide() {
    let rule = Adaptive {
        threshold: 0.2,
        min_samples: 16,
    };
    let renders = render(8, 64, 2048, rule);
    let mut values = Vec::new();
    let mut own_samples = Vec::new();
    let mut taken = Vec::new();
    for streams in &renders {
        for (i, pixel) in streams.pixels.iter().enumerate() {
            values.push(streams.value(i).0[0]);
            let all = pixel.running[0].sums[0] + pixel.running[1].sums[0];
            own_samples.push(all / f64::from(pixel.running[0].count + pixel.running[1].count));
        }
        taken.extend(streams.samples_taken());
    }
    // Adaptive indeed: pixels stop at counts far apart (those that met no bright sample first).
    let (fewest, most) = (taken.iter().min().unwrap(), taken.iter().max().unwrap());
    assert!(
        fewest * 4 < *most && *most < 2048,
        "stopped at {fewest}..{most} samples"
    );
    let z = z_score(&values, EXPECTED);
    assert!(z.abs() < 4.0, "two streams: z = {z:.2}");
    let z_own = z_score(&own_samples, EXPECTED);
    assert!(
        z_own < -4.0,
        "deciding on the samples kept should darken the image: z = {z_own:.2}"
    );
}

/// A stream fires only when its own estimate and its neighbours' meet the rule, it freezes the
/// other stream, and a pixel stops when both have fired, not before the minimum.
#[test]
fn streams_fire_by_their_own_samples_and_neighbours() {
    let rule = Adaptive {
        threshold: 0.1,
        min_samples: 8,
    };
    // Three pixels in a row; samples: stream 0 constant everywhere, stream 1 noisy at pixel 2.
    let mut streams = AdaptiveStreams::new(rule, 3, 3);
    let add = |streams: &mut AdaptiveStreams, noisy: f64| {
        streams.add([2, 2], |i| {
            let one = if i == 2 { noisy } else { 1.0 };
            [
                [2.0, 2.0, 2.0, 2.0],
                [2.0 * one, 2.0 * one, 2.0 * one, 2.0 * one * one],
            ]
        });
        streams.settle();
    };
    add(&mut streams, 1.0);
    assert!(
        streams.pixels.iter().all(|p| p.fired == [false; 2]),
        "before the minimum"
    );
    add(&mut streams, 5.0);
    // Stream 0 is quiet everywhere: it fired at every pixel and froze stream 1 there.
    assert!(streams.pixels.iter().all(|p| p.fired[0]));
    assert_eq!(streams.pixels[0].kept[1].count, 4);
    // Stream 1 is noisy at pixel 2, so pixels 1 and 2 (its neighbours) go on; pixel 0 stops.
    let fired1: Vec<bool> = streams.pixels.iter().map(|p| p.fired[1]).collect();
    assert_eq!(fired1, [true, false, false]);
    assert_eq!(streams.stopped(), &[8, 0, 0]);
    assert_eq!(streams.active(), 2);
    // Pixel 1's value: stream 0 up to now (stream 1 has not fired), stream 1 frozen at 4.
    let (value, count) = streams.value(1);
    assert_eq!(value[0], 1.0);
    assert_eq!(count, 8);
    // Pixel 2: stream 1's mean of 1 and 5 (frozen when stream 0 fired), stream 0's 1.
    assert_eq!(streams.value(2).0[0], (1.0 + 3.0) / 2.0);
    // Only the pixels still sampling take a batch.
    add(&mut streams, 1.0);
    assert_eq!(streams.samples_taken(), vec![8, 12, 12]);
}
