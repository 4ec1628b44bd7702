//! WGSL checks that need no GPU: every shader file parses and validates with naga (as part of the
//! entry-point modules it belongs to), and every GPU struct's size, alignment, member names and
//! member offsets in Rust match what naga computes for the WGSL struct.

use naga::proc::Layouter;
use naga::valid::{Capabilities, ValidationFlags, Validator};
use rt_gpu::shaders::{MODULES, files};

fn parse(name: &str, source: &str) -> naga::Module {
    naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)))
}

#[test]
fn every_module_parses_and_validates() {
    for module in MODULES {
        let source = module.source();
        let parsed = parse(module.name, &source);
        Validator::new(ValidationFlags::all(), Capabilities::all())
            .validate(&parsed)
            .unwrap_or_else(|e| panic!("{}: {}", module.name, e.emit_to_string(&source)));
    }
}

/// Every `.wgsl` file under `dir` (recursively), by path from the workspace root.
fn wgsl_files_under(root: &std::path::Path, dir: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut pending = vec![root.join(dir)];
    while let Some(folder) = pending.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                let relative = path.strip_prefix(root).unwrap().to_string_lossy();
                found.push(relative.replace('\\', "/"));
            }
        }
    }
    found
}

#[test]
fn every_wgsl_file_is_compiled_into_some_module() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut on_disk = wgsl_files_under(root, "shaders");
    on_disk.extend(wgsl_files_under(root, "crates/core/src"));
    for file in &on_disk {
        assert!(
            MODULES
                .iter()
                .any(|m| m.files.iter().any(|(name, _)| *name == file.as_str())),
            "{file} is in no shader module"
        );
    }
    for (name, _) in files() {
        assert!(
            on_disk.iter().any(|f| f == name),
            "a module names {name}, which does not exist"
        );
    }
}

/// The estimator's WGSL lives beside its Rust twin: every WGSL file in rt-core has a Rust file of
/// the same stem in the same folder, and that file exports exactly this text as its `WGSL` (the
/// text the kernels are composed of).
#[test]
fn every_estimator_wgsl_file_has_its_rust_twin_beside_it() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let twins = wgsl_files_under(root, "crates/core/src");
    assert!(twins.len() >= 13, "only {twins:?}");
    for file in &twins {
        let rust = root.join(file).with_extension("rs");
        let text = std::fs::read_to_string(&rust)
            .unwrap_or_else(|e| panic!("{file} has no Rust twin {}: {e}", rust.display()));
        let stem = std::path::Path::new(file)
            .file_name()
            .unwrap()
            .to_string_lossy();
        assert!(
            text.contains(&format!("pub const WGSL: &str = include_str!(\"{stem}\");")),
            "{} does not export {stem} as its WGSL",
            rust.display()
        );
        let on_disk = std::fs::read_to_string(root.join(file)).unwrap();
        let (_, composed) = files().into_iter().find(|(name, _)| name == file).unwrap();
        assert_eq!(composed, on_disk, "{file}: the modules hold other text");
    }
    // Only the entry points and what has no CPU twin stay in shaders/.
    let mut entry_files = wgsl_files_under(root, "shaders");
    entry_files.sort();
    assert_eq!(
        entry_files,
        [
            "shaders/preview.wgsl",
            "shaders/preview_blit.wgsl",
            "shaders/preview_glass.wgsl",
            "shaders/preview_shading.wgsl",
            "shaders/ray_query.wgsl",
            "shaders/trace.wgsl",
            "shaders/trace_rays.wgsl",
            "shaders/trace_rays_bvh.wgsl",
            "shaders/wavefront.wgsl",
        ]
    );
}

#[test]
fn gpu_struct_layouts_match_wgsl() {
    let source = rt_gpu::shaders::GPU_TYPES.1;
    let module = parse("gpu_types.wgsl", source);
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for rt_core::gpu_types::StructLayout {
        name,
        size,
        align,
        fields,
    } in rt_core::gpu_types::layouts()
    {
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("WGSL has no struct {name}"));
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("{name} is not a struct")
        };
        assert_eq!(*span as usize, size, "{name}: size (WGSL vs Rust)");
        assert_eq!(
            layouter[handle].alignment.round_up(1) as usize,
            align,
            "{name}: alignment (WGSL vs Rust)"
        );
        let wgsl: Vec<(String, usize)> = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .collect();
        let rust: Vec<(String, usize)> = fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
        assert_eq!(
            wgsl, rust,
            "{name}: member names and offsets (WGSL vs Rust)"
        );
    }
}

/// The work-group traversal stacks hold `MAX_WORKGROUP_INVOCATIONS` stacks of the deepest BVH the
/// builder makes, and fit the default 16 KiB of work-group memory.
#[test]
fn bvh_traversal_stacks_fit_the_work_group_and_the_deepest_bvh() {
    for module in MODULES {
        let source = module.source();
        if !source.contains("bvh_stacks") {
            continue;
        }
        let parsed = parse(module.name, &source);
        let mut layouter = Layouter::default();
        layouter.update(parsed.to_ctx()).unwrap();
        let (_, var) = parsed
            .global_variables
            .iter()
            .find(|(_, v)| v.name.as_deref() == Some("bvh_stacks"))
            .unwrap();
        assert_eq!(var.space, naga::AddressSpace::WorkGroup);
        let bytes = layouter[var.ty].size as usize;
        // BVH2 stacks hold node indices; wide ones hold groups of two words.
        let (depth, entry) = if source.contains("alias BvhNodeRecord = WideBvhNode;") {
            (rt_core::bvh::MAX_WIDE_BVH_DEPTH, 8)
        } else {
            (rt_core::bvh::MAX_BVH_DEPTH, 4)
        };
        assert_eq!(
            bytes,
            rt_gpu::MAX_WORKGROUP_INVOCATIONS as usize * depth * entry,
            "{}: bvh_stacks size",
            module.name
        );
        assert!(
            bytes <= 16384,
            "{}: over the default work-group memory",
            module.name
        );
        assert!(
            source.contains(&format!("const BVH_STACK_SIZE: u32 = {depth}u;")),
            "{}: BVH_STACK_SIZE must equal the deepest BVH the builder allows ({depth})",
            module.name
        );
    }
}

/// The wavefront renderer sizes its path and shadow-ray queues and writes the queue lengths from
/// these Rust constants and mirror: they must match the WGSL structs.
#[test]
fn wavefront_struct_layouts_match_wgsl() {
    use rt_gpu::wavefront::{SHADOW_RAY_BYTES, WAVE_PATH_BYTES, WAVE_QUEUES_FIELDS, WaveQueues};
    let source = rt_gpu::shaders::WAVEFRONT_WIDE.source();
    let module = parse("wavefront_wide", &source);
    let strukt = |name: &str| {
        module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .and_then(|(_, t)| match &t.inner {
                naga::TypeInner::Struct { members, span } => Some((members.clone(), *span)),
                _ => None,
            })
            .unwrap_or_else(|| panic!("WGSL has no struct {name}"))
    };
    assert_eq!(
        u64::from(strukt("WavePath").1),
        WAVE_PATH_BYTES,
        "WavePath size"
    );
    assert_eq!(
        u64::from(strukt("ShadowRay").1),
        SHADOW_RAY_BYTES,
        "ShadowRay size"
    );
    let (members, span) = strukt("WaveQueues");
    assert_eq!(span as usize, size_of::<WaveQueues>(), "WaveQueues size");
    let wgsl: Vec<(String, usize)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .collect();
    let rust: Vec<(String, usize)> = WAVE_QUEUES_FIELDS
        .iter()
        .map(|(n, o)| (n.to_string(), *o))
        .collect();
    assert_eq!(wgsl, rust, "WaveQueues member names and offsets");
    // And the Rust struct has them where the list says.
    use std::mem::offset_of;
    let actual = [
        ("groups_x", offset_of!(WaveQueues, groups)),
        ("rays", offset_of!(WaveQueues, rays)),
        ("next_rays", offset_of!(WaveQueues, next_rays)),
        ("shadows", offset_of!(WaveQueues, shadows)),
        ("parity", offset_of!(WaveQueues, parity)),
        ("_pad", offset_of!(WaveQueues, _pad)),
    ];
    for (name, offset) in actual {
        assert!(
            WAVE_QUEUES_FIELDS.contains(&(name, offset)),
            "WaveQueues::{name} is at {offset} in Rust"
        );
    }
}

/// The bind-group table (`rt_gpu::bindings`, from which every tracing layout and bind group is
/// built) lists exactly the bindings each kernel's WGSL declares, over rt's BVHs and over ray
/// queries: number, name, uniform, storage or acceleration structure, and read-only or read-write.
#[test]
fn the_binding_table_matches_every_tracing_kernel() {
    use naga::{AddressSpace, StorageAccess};
    use rt_gpu::Kernel::{Megakernel, Wavefront};
    use rt_gpu::bindings::{self, Access};
    use rt_gpu::shaders::{TRACE, TRACE_HW, TRACE_WIDE, WAVEFRONT, WAVEFRONT_HW, WAVEFRONT_WIDE};
    for (module, kernel, ray_query) in [
        (&TRACE, Megakernel, false),
        (&TRACE_WIDE, Megakernel, false),
        (&TRACE_HW, Megakernel, true),
        (&WAVEFRONT, Wavefront, false),
        (&WAVEFRONT_WIDE, Wavefront, false),
        (&WAVEFRONT_HW, Wavefront, true),
    ] {
        let parsed = parse(module.name, &module.source());
        let mut in_wgsl: Vec<(u32, String, Access)> = parsed
            .global_variables
            .iter()
            .filter_map(|(_, var)| {
                let binding = var.binding.as_ref()?;
                assert_eq!(binding.group, 0, "{}: {:?}", module.name, var.name);
                let access = match var.space {
                    AddressSpace::Uniform => Access::Uniform,
                    AddressSpace::Storage { access } if access.contains(StorageAccess::STORE) => {
                        Access::ReadWrite
                    }
                    AddressSpace::Storage { .. } => Access::Read,
                    AddressSpace::Handle => Access::AccelerationStructure,
                    other => panic!("{}: {:?} in {other:?}", module.name, var.name),
                };
                Some((
                    binding.binding,
                    var.name.clone().unwrap_or_default(),
                    access,
                ))
            })
            .collect();
        in_wgsl.sort_by_key(|(number, _, _)| *number);
        let table: Vec<(u32, String, Access)> = bindings::of(kernel, ray_query)
            .map(|b| (b.number, b.name.to_string(), b.access))
            .collect();
        assert_eq!(
            table, in_wgsl,
            "{}: rt_gpu::bindings against the WGSL",
            module.name
        );
    }
}

/// The constants the CPU and the kernels share (material and light kinds, the no-texture
/// sentinel, material flags, texture slots and sampler bits) have the same values in `rt_core::gpu_types` and in `crates/core/src/gpu_types.wgsl`.
#[test]
fn shared_constants_match_wgsl() {
    use rt_core::gpu_types::{self, NO_TEXTURE};
    use rt_core::math::{glass_energy, layers};
    use rt_core::{Filter, TextureSampler, Wrap};
    // The s-wrap bits of a sampler (t repeats), or its filter bit.
    let sampler_bits = |wrap: Wrap, filter: Filter| {
        TextureSampler {
            wrap_s: wrap,
            wrap_t: Wrap::Repeat,
            filter,
        }
        .bits()
    };
    let module = &rt_gpu::shaders::TRACE;
    let parsed = parse(module.name, &module.source());
    let value = |name: &str| -> u32 {
        let (_, constant) = parsed
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no WGSL constant {name}"));
        match parsed.global_expressions[constant.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref other => panic!("{name} = {other:?}, not a u32 literal"),
        }
    };
    for kind in rt_core::MaterialKind::ALL {
        assert_eq!(value(kind.wgsl_constant()), kind.tag(), "{kind:?}");
        if let Some(switch) = kind.pipeline_switch() {
            assert!(
                parsed
                    .overrides
                    .iter()
                    .any(|(_, o)| o.name.as_deref() == Some(switch)),
                "{kind:?}: the kernels declare no override {switch}"
            );
        }
    }
    // Every light tag the path tracer's records use, and no other LIGHT_* constant but the
    // light tree's depth: the kernels' list is the table's.
    for tag in rt_core::LightTag::ALL {
        let defined = parsed
            .constants
            .iter()
            .any(|(_, c)| c.name.as_deref() == Some(tag.wgsl_constant()));
        assert_eq!(defined, tag.in_path_tracer(), "{tag:?} in the kernels");
        if defined {
            assert_eq!(value(tag.wgsl_constant()), tag.tag(), "{tag:?}");
        }
    }
    for (_, c) in parsed.constants.iter() {
        let name = c.name.as_deref().unwrap_or("");
        assert!(
            !name.starts_with("LIGHT_")
                || name == "LIGHT_TREE_DEPTH"
                || rt_core::LightTag::ALL
                    .iter()
                    .any(|t| t.wgsl_constant() == name),
            "{name}: a light kind the LightTag table lacks"
        );
    }
    for (wgsl, rust) in [
        ("ENERGY_SIDE", rt_core::math::microfacet::ENERGY_SIDE as u32),
        ("NO_TEXTURE", NO_TEXTURE),
        ("THIN_WALLED", gpu_types::THIN_WALLED),
        ("ALPHA_MASK", gpu_types::ALPHA_MASK),
        ("ALPHA_BLEND", gpu_types::ALPHA_BLEND),
        ("TANGENTS", gpu_types::TANGENTS),
        ("SHADOW_CATCHER", gpu_types::SHADOW_CATCHER),
        (
            "AOV_VECS",
            (rt_gpu::renderer::AOV_BYTES_PER_PIXEL / 16) as u32,
        ),
        ("SLOT_BASE", gpu_types::SLOT_BASE),
        (
            "SLOT_METALLIC_ROUGHNESS",
            gpu_types::SLOT_METALLIC_ROUGHNESS,
        ),
        ("SLOT_NORMAL", gpu_types::SLOT_NORMAL),
        ("SLOT_EMISSION", gpu_types::SLOT_EMISSION),
        ("SAMPLER_BITS", gpu_types::SAMPLER_BITS),
        ("TABLE_CONDUCTOR", layers::TABLE_CONDUCTOR as u32),
        ("TABLE_COAT", layers::TABLE_COAT as u32),
        ("TABLE_SHEEN", layers::TABLE_SHEEN as u32),
        ("TABLE_GLASS", layers::TABLE_GLASS as u32),
        ("GLASS_MU", glass_energy::GLASS_MU as u32),
        ("GLASS_ROUGHNESS", glass_energy::GLASS_ROUGHNESS as u32),
        ("GLASS_IOR", glass_energy::GLASS_IOR as u32),
        // The sampler bits texture.wgsl decodes, as `TextureSampler::bits` packs them.
        (
            "WRAP_CLAMP",
            sampler_bits(Wrap::ClampToEdge, Filter::Linear),
        ),
        (
            "WRAP_MIRROR",
            sampler_bits(Wrap::MirroredRepeat, Filter::Linear),
        ),
        (
            "FILTER_NEAREST",
            sampler_bits(Wrap::Repeat, Filter::Nearest),
        ),
    ] {
        assert_eq!(value(wgsl), rust, "{wgsl}");
    }
    for (wgsl, rust) in [
        ("MIN_ALPHA", rt_core::math::microfacet::MIN_ALPHA),
        ("COAT_IOR", rt_core::math::coat::COAT_IOR),
        ("GLASS_MU_MIN", rt_core::math::glass_energy::MU_MIN),
        (
            "SHEEN_MIN_ROUGHNESS",
            rt_core::math::sheen::SHEEN_MIN_ROUGHNESS,
        ),
        (
            "LIT_THROUGH_MIN_ALPHA",
            rt_core::estimator::surface::LIT_THROUGH_MIN_ALPHA,
        ),
    ] {
        let (_, constant) = parsed
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(wgsl))
            .unwrap_or_else(|| panic!("no WGSL constant {wgsl}"));
        assert!(
            matches!(
                parsed.global_expressions[constant.init],
                naga::Expression::Literal(naga::Literal::F32(v)) if v == rust
            ),
            "{wgsl}"
        );
    }
}
