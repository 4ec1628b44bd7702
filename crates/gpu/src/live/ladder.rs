//! The resolution ladder (Blender's "pixel size"): after a change the viewport renders with big
//! pixels first, so the first new image costs a fraction of a full-resolution sample, then steps
//! finer, each step shown once every pixel has a sample, and refines at full resolution.

/// Screen pixels per rendered pixel, coarsest first.
pub const DEFAULT_PIXEL_SIZES: [u32; 5] = [16, 8, 4, 2, 1];

/// Steps keep at least this many rendered pixels on the short side (coarser ones show nothing).
const MIN_SIDE: u32 = 8;

/// The first step needs no more pixels than this by default: a coarser step is dropped when the
/// next finer one is already this small (a 640x480 view starts at 8, a 1280x720 one at 16). Its
/// sample is what a camera move waits for (about 10 ms of lavapipe on the Cornell box).
pub const FIRST_STEP_PIXELS: u32 = 8192;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ladder {
    steps: Vec<u32>,
    index: usize,
}

impl Ladder {
    /// The steps of `pixel_sizes` that suit a `size` view, coarsest first, always ending at 1,
    /// starting at the finest whose next step has more than `first_step_pixels` pixels.
    pub fn new(pixel_sizes: &[u32], size: [u32; 2], first_step_pixels: u32) -> Ladder {
        let short = size[0].min(size[1]);
        let mut steps: Vec<u32> = pixel_sizes
            .iter()
            .copied()
            .filter(|&s| s > 1 && short / s >= MIN_SIDE)
            .collect();
        steps.sort_unstable_by(|a, b| b.cmp(a));
        steps.dedup();
        steps.push(1);
        let pixels = |s: u32| size[0].div_ceil(s) * size[1].div_ceil(s);
        while steps.len() > 1 && pixels(steps[1]) <= first_step_pixels {
            steps.remove(0);
        }
        Ladder { steps, index: 0 }
    }

    pub fn pixel_size(&self) -> u32 {
        self.steps[self.index]
    }

    /// The rendered image's size at this step (rounded up: the view crops the last big pixels).
    pub fn resolution(&self, size: [u32; 2]) -> [u32; 2] {
        let s = self.pixel_size();
        [size[0].div_ceil(s).max(1), size[1].div_ceil(s).max(1)]
    }

    pub fn is_final(&self) -> bool {
        self.index + 1 == self.steps.len()
    }

    /// Steps one finer once this step has a whole sample, unless the user is still dragging (then
    /// the view stays at the coarsest step, which follows the mouse). Returns whether it moved.
    pub fn advance(&mut self, samples_at_step: u32, interacting: bool) -> bool {
        if self.is_final() || samples_at_step == 0 || (interacting && self.index == 0) {
            return false;
        }
        self.index += 1;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_change_starts_coarse_and_reaches_full_resolution_by_itself() {
        let mut ladder = Ladder::new(&DEFAULT_PIXEL_SIZES, [1280, 720], FIRST_STEP_PIXELS);
        assert_eq!(ladder.pixel_size(), 16);
        assert_eq!(ladder.resolution([1280, 720]), [80, 45]);
        let mut seen = vec![ladder.pixel_size()];
        // Each step's first whole sample moves it on, with no user input.
        while ladder.advance(1, false) {
            seen.push(ladder.pixel_size());
        }
        assert_eq!(seen, [16, 8, 4, 2, 1]);
        assert!(ladder.is_final());
        assert_eq!(ladder.resolution([1280, 720]), [1280, 720]);
    }

    #[test]
    fn it_waits_for_a_whole_sample_and_holds_while_the_user_drags() {
        let mut ladder = Ladder::new(&[8, 4, 2, 1], [640, 480], 0);
        assert!(!ladder.advance(0, false), "no sample yet");
        assert!(!ladder.advance(5, true), "dragging keeps the coarse step");
        assert_eq!(ladder.pixel_size(), 8);
        assert!(ladder.advance(1, false));
        assert_eq!(ladder.pixel_size(), 4);
    }

    #[test]
    fn small_views_skip_steps_that_would_show_nothing() {
        assert_eq!(
            Ladder::new(&DEFAULT_PIXEL_SIZES, [640, 480], FIRST_STEP_PIXELS).pixel_size(),
            8
        );
        // Small views start finer: 96x96 at 4 would be 576 pixels, at 2 still 2304.
        assert_eq!(
            Ladder::new(&DEFAULT_PIXEL_SIZES, [96, 96], FIRST_STEP_PIXELS).pixel_size(),
            2
        );
        assert_eq!(
            Ladder::new(&[4, 2, 1], [400, 400], FIRST_STEP_PIXELS).pixel_size(),
            4
        );
        let tiny = Ladder::new(&DEFAULT_PIXEL_SIZES, [5, 3], 0);
        assert!(tiny.is_final());
        assert_eq!(tiny.resolution([5, 3]), [5, 3]);
        // Odd sizes round up: the last big pixel is cropped by the view.
        let odd = Ladder::new(&[4, 1], [101, 99], 0);
        assert_eq!(odd.resolution([101, 99]), [26, 25]);
    }
}
