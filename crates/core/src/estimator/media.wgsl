// The media a path is in: a stack of two medium ids, and the medium an id names. Mirrors
// crates/core/src/estimator/media.rs one-to-one.

// The medium stack (media.rs `media_top`, `media_enter`, `media_leave`, `medium_of`): id 0 the
// scene's fog, m + 1 material m's interior.
fn media_top(media: u32) -> u32 {
    return media & 0xffffu;
}

fn media_enter(media: u32, material: u32) -> u32 {
    if (material >= 0xffffu) {
        return media;
    }
    return (media << 16u) | (material + 1u);
}

fn media_leave(media: u32, material: u32) -> u32 {
    let id = material + 1u;
    if ((media & 0xffffu) == id) {
        return media >> 16u;
    }
    if ((media >> 16u) == id) {
        return media & 0xffffu;
    }
    return media;
}

fn medium_of(id: u32) -> Medium {
    if (id == 0u) {
        return frame.fog;
    }
    return materials[id - 1u].medium;
}
