//! Adapter and device selection.

#[cfg(feature = "testing")]
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use crate::error::{GpuError, Result};
use crate::pipeline_cache::PipelineCache;

/// Which adapter to use.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum AdapterChoice {
    /// A discrete or integrated GPU if there is one, else whatever exists (e.g. lavapipe).
    #[default]
    Auto,
    /// A software adapter such as Mesa lavapipe (a GPU emulated on the CPU): repeatable results,
    /// used by tests. Not rt's native CPU backend (`rt-cli --device cpu`).
    Software,
    /// The first adapter whose name contains this text (case-insensitive).
    Named(String),
}

impl std::str::FromStr for AdapterChoice {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "auto" | "" => AdapterChoice::Auto,
            "lavapipe" | "llvmpipe" | "software" | "cpu" => AdapterChoice::Software,
            _ => AdapterChoice::Named(s.to_string()),
        })
    }
}

/// How to open the device, beyond which adapter. rt-gpu reads no environment variables: the
/// binaries (`rt-cli`, `rt`) read `RT_NO_RAY_QUERY` and pass it here.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceOptions {
    /// Leave ray queries off even where the adapter has them, should a driver misbehave with them
    /// enabled (`Trace::Auto` then traces with rt's BVH, and `Trace::Hardware` is an error).
    pub no_ray_queries: bool,
}

impl DeviceOptions {
    /// What `RT_NO_RAY_QUERY` asks, given its value as a binary read it: set to anything but
    /// empty or `0`, ray queries stay off. (The variable's meaning in one place, for both
    /// binaries.)
    pub fn from_no_ray_query_var(value: Option<&std::ffi::OsStr>) -> Self {
        DeviceOptions {
            no_ray_queries: value.is_some_and(|v| !v.is_empty() && v != "0"),
        }
    }
}

/// An open device with its queue, and the pipelines built on it so far.
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub(crate) pipelines: PipelineCache,
    /// Why the device was lost, once it has been.
    lost: Arc<Mutex<Option<String>>>,
    /// Fault injection (`inject_out_of_memory`): the scoped operation this many calls on fails as
    /// out of memory; 0 is off. Only in test builds.
    #[cfg(feature = "testing")]
    out_of_memory_in: AtomicU32,
}

/// "name (backend, driver version)", e.g. "llvmpipe (LLVM 19.1.7, 256 bits) (Vulkan, Mesa 25.0.7)":
/// lavapipe's speed and limits depend on the Mesa release (docs/performance.md), so summaries and
/// benchmark records name it.
pub fn adapter_label(info: &wgpu::AdapterInfo) -> String {
    let driver = [info.driver.as_str(), info.driver_info.as_str()]
        .into_iter()
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>();
    // lavapipe reports driver "llvmpipe" and driver_info "Mesa 25.0.7 (LLVM 19.1.7)"; keep the
    // version and not a repeat of the name.
    let driver = match driver.as_slice() {
        [] => String::new(),
        [one] => format!(", {one}"),
        [name, version] if info.name.contains(name) => format!(", {version}"),
        [name, version] => format!(", {name} {version}"),
        _ => String::new(),
    };
    format!("{} ({:?}{driver})", info.name, info.backend)
}

/// (major, minor) of a driver info such as "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)".
pub fn mesa_version(driver_info: &str) -> Option<(u32, u32)> {
    let version = driver_info.split("Mesa ").nth(1)?;
    let mut parts = version.split(['.', '-', ' ']);
    Some((parts.next()?.parse().ok()?, parts.next()?.parse().ok()?))
}

/// wgpu's token for its experimental features, of which rt uses only `EXPERIMENTAL_RAY_QUERY`.
#[allow(unsafe_code)] // the one unsafe call in rt; see SAFETY below
fn experimental_features_enabled() -> wgpu::ExperimentalFeatures {
    // SAFETY: the token is unsafe because experimental features may have bugs or API changes
    // without notice. rt uses ray queries through the safe wgpu API only, for traversal that its
    // own BVH code also does, and the tests check the images agree (tests/ray_query.rs); the
    // feature is requested only where the adapter reports it.
    unsafe { wgpu::ExperimentalFeatures::enabled() }
}

/// Every adapter wgpu finds (Vulkan, Metal or DX12 ones, else GL ones), with the instances they
/// came from, kept alive while the adapters are used.
async fn enumerate_adapters() -> (Vec<wgpu::Adapter>, Vec<wgpu::Instance>) {
    // GL only as a fallback, in an instance of its own: creating its EGL display is slow and
    // logs errors on machines where Vulkan works (Mesa 25's EGL without a DRI driver).
    let described = || wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    let allowed = described().backends;
    let primary = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: allowed & wgpu::Backends::PRIMARY,
        ..described()
    });
    let mut adapters = primary.enumerate_adapters(wgpu::Backends::PRIMARY).await;
    if adapters.is_empty() && allowed.contains(wgpu::Backends::GL) {
        let gl = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::GL,
            ..described()
        });
        adapters = gl.enumerate_adapters(wgpu::Backends::GL).await;
        return (adapters, vec![primary, gl]);
    }
    (adapters, vec![primary])
}

/// The name of a hardware GPU wgpu can use (discrete, integrated or virtual), if there is one:
/// what `--device auto` asks before it chooses a backend. Software adapters (lavapipe,
/// SwiftShader, WARP) do not count. Opens no device.
pub fn hardware_gpu() -> Option<String> {
    let (adapters, _instances) = pollster::block_on(enumerate_adapters());
    adapters.iter().map(|a| a.get_info()).find_map(|info| {
        matches!(
            info.device_type,
            wgpu::DeviceType::DiscreteGpu
                | wgpu::DeviceType::IntegratedGpu
                | wgpu::DeviceType::VirtualGpu
        )
        .then_some(info.name)
    })
}

impl GpuContext {
    /// Opens `choice`'s device with the default `DeviceOptions` (ray queries where it has them).
    pub fn new(choice: &AdapterChoice) -> Result<Self> {
        Self::with_options(choice, DeviceOptions::default())
    }

    /// Opens `choice`'s device as `options` ask.
    pub fn with_options(choice: &AdapterChoice, options: DeviceOptions) -> Result<Self> {
        pollster::block_on(Self::new_async(choice, options))
    }

    async fn new_async(choice: &AdapterChoice, options: DeviceOptions) -> Result<Self> {
        let (adapters, _instances) = enumerate_adapters().await;
        let names: Vec<String> = adapters
            .iter()
            .map(|a| format!("{} ({:?})", a.get_info().name, a.get_info().backend))
            .collect();
        let rank = |a: &wgpu::Adapter| {
            let info = a.get_info();
            // Prefer Vulkan/Metal/DX12 over GL, then by device type.
            let backend = if info.backend == wgpu::Backend::Gl {
                0
            } else {
                1
            };
            let kind = match (choice, info.device_type) {
                (AdapterChoice::Software, wgpu::DeviceType::Cpu) => 4,
                (AdapterChoice::Software, _) => 0,
                (_, wgpu::DeviceType::DiscreteGpu) => 4,
                (_, wgpu::DeviceType::IntegratedGpu) => 3,
                (_, wgpu::DeviceType::VirtualGpu) => 2,
                (_, wgpu::DeviceType::Cpu) => 1,
                _ => 0,
            };
            kind * 2 + backend
        };
        let adapter = match choice {
            AdapterChoice::Named(name) => {
                let needle = name.to_ascii_lowercase();
                adapters
                    .into_iter()
                    .find(|a| a.get_info().name.to_ascii_lowercase().contains(&needle))
            }
            AdapterChoice::Software => adapters
                .into_iter()
                .filter(|a| a.get_info().device_type == wgpu::DeviceType::Cpu)
                .max_by_key(rank),
            AdapterChoice::Auto => adapters.into_iter().max_by_key(rank),
        };
        let Some(adapter) = adapter else {
            let found = if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            };
            return Err(GpuError::NoAdapter(format!(
                " matching {choice:?} (adapters found: {found}); on Debian/Ubuntu install a Vulkan driver, e.g. `sudo apt-get install -y mesa-vulkan-drivers`"
            )));
        };
        let info = adapter.get_info();
        // Ray queries where the adapter has them (`Trace::Hardware`), unless the options leave
        // them off.
        let ray_query = adapter
            .features()
            .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
            && !options.no_ray_queries;
        let (required_features, experimental_features) = if ray_query {
            (
                wgpu::Features::EXPERIMENTAL_RAY_QUERY,
                experimental_features_enabled(),
            )
        } else {
            (
                wgpu::Features::empty(),
                wgpu::ExperimentalFeatures::disabled(),
            )
        };
        let (device, queue): (wgpu::Device, wgpu::Queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("rt"),
                required_features,
                required_limits: adapter.limits(),
                experimental_features,
                ..Default::default()
            })
            .await
            .map_err(|e| GpuError::Device(e.to_string()))?;
        log::info!("adapter: {} ({:?})", adapter_label(&info), info.device_type);
        let lost: Arc<Mutex<Option<String>>> = Arc::default();
        {
            let lost = lost.clone();
            device.set_device_lost_callback(move |reason, message| {
                log::error!("GPU device lost ({reason:?}): {message}");
                if let Ok(mut slot) = lost.lock() {
                    slot.get_or_insert(format!("{reason:?}: {message}"));
                }
            });
        }
        // wgpu's default handler panics on errors outside an error scope (e.g. on a lost device);
        // operations check `alive()` and scopes instead, so log them.
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| {
            log::error!("uncaptured GPU error: {e}");
        }));
        Ok(GpuContext {
            adapter,
            device,
            queue,
            info,
            pipelines: PipelineCache::default(),
            lost,
            #[cfg(feature = "testing")]
            out_of_memory_in: AtomicU32::new(0),
        })
    }

    /// The Mesa release of a Mesa driver (lavapipe's speed, limits and memory behaviour depend on
    /// it: docs/performance.md), as (major, minor); `None` for other drivers.
    pub fn mesa_version(&self) -> Option<(u32, u32)> {
        mesa_version(&self.info.driver_info)
    }

    /// Whether the device can trace with the driver's ray queries (`Trace::Hardware`).
    pub fn has_ray_queries(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
    }

    /// `Trace::Auto` resolved for `scene` on this device (the others as they are): ray queries on
    /// GPUs that offer them, else rt's BVH. Lavapipe's ray queries are software too, and rt's
    /// traversal measured faster there (docs/performance.md); an empty scene has nothing to build
    /// them over.
    pub fn resolve_trace(&self, trace: crate::Trace, scene: &rt_core::GpuScene) -> crate::Trace {
        use crate::Trace;
        match trace {
            Trace::Auto
                if self.has_ray_queries()
                    && self.info.device_type != wgpu::DeviceType::Cpu
                    && !scene.triangles.is_empty() =>
            {
                Trace::Hardware
            }
            Trace::Auto => Trace::Bvh,
            chosen => chosen,
        }
    }

    /// "name (backend, driver)" for summaries: see `adapter_label`.
    pub fn adapter_label(&self) -> String {
        adapter_label(&self.info)
    }

    /// The test suites' policy for a machine without a GPU adapter, in one place: the test context
    /// prefers a CPU adapter (lavapipe) so results are repeatable; without any adapter a test fails
    /// when `CI` is set (it never passes silently there) and otherwise prints why and returns
    /// `None`, for the test to return early. Test code, so behind the `testing` feature (the
    /// suites' dev-dependencies turn it on): the shipping library reads no `CI`.
    #[cfg(feature = "testing")]
    pub fn for_tests() -> Option<GpuContext> {
        let found = GpuContext::new(&AdapterChoice::Software)
            .or_else(|_| GpuContext::new(&AdapterChoice::Auto));
        match found {
            Ok(ctx) => {
                eprintln!("GPU tests on {}", ctx.adapter_label());
                Some(ctx)
            }
            Err(e) if std::env::var_os("CI").is_some() => {
                panic!("CI is set but there is no GPU adapter: {e}")
            }
            Err(e) => {
                eprintln!(
                    "SKIPPED: no GPU adapter ({e}); install mesa-vulkan-drivers (scripts/ensure-vulkan) to run GPU tests"
                );
                None
            }
        }
    }

    /// Checks one buffer against the binding and buffer size limits.
    pub fn check_buffer(&self, buffer: &'static str, size: u64) -> Result<()> {
        let limits = self.device.limits();
        let binding = limits.max_storage_buffer_binding_size;
        if size > binding {
            return Err(GpuError::TooLarge {
                buffer,
                size,
                limit: binding,
                what: "max_storage_buffer_binding_size",
            });
        }
        if size > limits.max_buffer_size {
            return Err(GpuError::TooLarge {
                buffer,
                size,
                limit: limits.max_buffer_size,
                what: "max_buffer_size",
            });
        }
        Ok(())
    }

    /// An error once the device has been lost.
    pub fn alive(&self) -> Result<()> {
        match self.lost.lock().ok().and_then(|l| l.clone()) {
            Some(reason) => Err(GpuError::DeviceLost(reason)),
            None => Ok(()),
        }
    }

    /// Fault injection for tests: the `operations`-th GPU operation from now (each `scoped` call,
    /// counting from 1) fails with `GpuError::OutOfMemory` without running, as one whose
    /// allocation failed. Real out-of-memory errors cannot be provoked on demand (lavapipe takes
    /// host memory until the system's runs out); this drives the same error path. Behind the
    /// `testing` feature, as `crate::faults` is.
    #[cfg(feature = "testing")]
    pub fn inject_out_of_memory(&self, operations: u32) {
        self.out_of_memory_in.store(operations, Ordering::SeqCst);
    }

    /// Runs `f` and turns any wgpu validation error it caused into `GpuError::Wgpu`, and an
    /// out-of-memory error into `GpuError::OutOfMemory`.
    pub fn scoped<T>(&self, f: impl FnOnce() -> T) -> Result<T> {
        #[cfg(feature = "testing")]
        {
            let countdown =
                self.out_of_memory_in
                    .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| n.checked_sub(1));
            if countdown == Ok(1) {
                return Err(GpuError::OutOfMemory("injected by a test".into()));
            }
        }
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = f();
        let v = pollster::block_on(validation.pop());
        let o = pollster::block_on(oom.pop());
        if v.is_some() || o.is_some() {
            // A destroyed or lost device makes every later object invalid, but wgpu calls the
            // device-lost callback only from a poll that finds the queue empty: wait for it, so
            // the error names the cause (an error path: the wait costs nothing that matters).
            let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        }
        self.alive()?;
        match (v, o) {
            (_, Some(e)) => Err(GpuError::OutOfMemory(e.to_string())),
            (Some(e), None) => Err(GpuError::Wgpu(e.to_string())),
            (None, None) => Ok(value),
        }
    }
}
