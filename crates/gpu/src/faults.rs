//! What the test suites inject into a render (`rt-cli render`'s device-lost, out-of-memory and
//! tiling tests). Only with rt-gpu's `testing` feature, which the suites' dev-dependencies turn on
//! (and with it the binaries `cargo test` builds for them): a shipping build reads no variable and
//! injects nothing. The variables are read here and nowhere else.

use crate::context::GpuContext;

/// After how many batches to inject each fault (none by default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faults {
    /// Destroy the device (`RT_FAULT_LOSE_DEVICE_AFTER_BATCHES`).
    lose_device_after: Option<u32>,
    /// Fail the next GPU operation as out of memory (`RT_FAULT_OUT_OF_MEMORY_AFTER_BATCHES`).
    out_of_memory_after: Option<u32>,
}

impl Faults {
    /// The faults the test environment asks for; none without the `testing` feature.
    pub fn from_test_env() -> Self {
        #[cfg(feature = "testing")]
        {
            Faults {
                lose_device_after: test_variable("RT_FAULT_LOSE_DEVICE_AFTER_BATCHES"),
                out_of_memory_after: test_variable("RT_FAULT_OUT_OF_MEMORY_AFTER_BATCHES"),
            }
        }
        #[cfg(not(feature = "testing"))]
        Faults::default()
    }

    /// Injects what is due before the batch that follows `batches` batches.
    pub fn before_batch(&self, ctx: &GpuContext, batches: u32) {
        if self.lose_device_after == Some(batches) {
            ctx.device.destroy();
        }
        #[cfg(feature = "testing")]
        if self.out_of_memory_after == Some(batches) {
            ctx.inject_out_of_memory(1);
        }
    }
}

/// A smaller largest accumulation buffer than the adapter's, where a test asks for one
/// (`RT_MAX_ACCUMULATION_BYTES`: tests render small images in tiles with it); `None` without the
/// `testing` feature.
pub fn max_accumulation_bytes() -> Option<u64> {
    #[cfg(feature = "testing")]
    return test_variable("RT_MAX_ACCUMULATION_BYTES");
    #[cfg(not(feature = "testing"))]
    None
}

#[cfg(feature = "testing")]
fn test_variable<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.trim().parse().ok())
}
