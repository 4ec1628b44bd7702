//! `render --frames A..B` and `--turntable N`: an animation rendered frame by frame, each a
//! render of its own (so each can be a separate job: one Slurm array task or Kubernetes pod per
//! frame) written to OUT.NNNN.EXT as Blender numbers its frames.

use std::path::{Path, PathBuf};

use clap::Args;

#[derive(Args, Debug, Clone, Default)]
pub struct AnimationArgs {
    /// Render frames A to B (both included, as Blender's frame range; one number for a single
    /// frame) of the scene's animation (a glTF file's, or a project's saved from one): frame N
    /// shows the scene at time (N − 1) / fps, so frame 1 is its start. Each frame is written to OUT.NNNN.EXT.
    #[arg(long, value_name = "A..B", value_parser = parse_frames)]
    pub frames: Option<[u32; 2]>,
    /// Frames per second of --frames.
    #[arg(long, default_value_t = 24.0, value_name = "FPS")]
    pub fps: f32,
    /// Orbit the camera once about the vertical axis through the scene's centre in N frames, at
    /// its distance and elevation (frames 1..N unless --frames picks some; frame 1 is the
    /// camera as it stands). Works on any scene, with or without an animation.
    #[arg(long, value_name = "N")]
    pub turntable: Option<u32>,
}

fn parse_frames(s: &str) -> Result<[u32; 2], String> {
    let number = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{t}' is not a frame number (in '{s}'; expected A..B)"))
    };
    let [a, b] = match s.split_once("..") {
        Some((a, b)) => [number(a)?, number(b)?],
        None => [number(s)?; 2],
    };
    if a == 0 || b < a {
        return Err(format!(
            "frames '{s}': expected A..B with 1 <= A <= B (frame 1 is the start)"
        ));
    }
    Ok([a, b])
}

/// One frame to render: its number, the animation time and the turntable's turn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub number: u32,
    pub time: f32,
    pub turns: Option<f32>,
}

impl AnimationArgs {
    /// The frames asked for, or `None` for a still image.
    pub fn frames(&self) -> anyhow::Result<Option<Vec<Frame>>> {
        if !(self.fps.is_finite() && self.fps > 0.0) {
            anyhow::bail!("--fps must be a positive number, got {}", self.fps);
        }
        if self.turntable == Some(0) {
            anyhow::bail!("--turntable needs at least one frame");
        }
        let range = match (self.frames, self.turntable) {
            (None, None) => return Ok(None),
            (Some(r), _) => r,
            (None, Some(n)) => [1, n],
        };
        Ok(Some(
            (range[0]..=range[1])
                .map(|number| Frame {
                    number,
                    time: (number - 1) as f32 / self.fps,
                    turns: self.turntable.map(|n| (number - 1) as f32 / n as f32),
                })
                .collect(),
        ))
    }
}

/// OUT.EXT as OUT.NNNN.EXT (four digits at least, as Blender's `####`).
pub fn numbered(output: &Path, number: u32) -> PathBuf {
    let stem = output
        .file_stem()
        .map_or_else(|| "render".into(), |s| s.to_string_lossy().into_owned());
    let name = match output.extension() {
        Some(ext) => format!("{stem}.{number:04}.{}", ext.to_string_lossy()),
        None => format!("{stem}.{number:04}"),
    };
    output.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_times_turns_and_names() {
        assert_eq!(parse_frames("3..5"), Ok([3, 5]));
        assert_eq!(parse_frames("7"), Ok([7, 7]));
        assert!(parse_frames("5..3").is_err() && parse_frames("0..2").is_err());
        assert!(parse_frames("a..b").is_err());
        let args = AnimationArgs {
            frames: Some([2, 3]),
            fps: 10.0,
            turntable: None,
        };
        let frames = args.frames().unwrap().unwrap();
        assert_eq!(frames.len(), 2);
        assert_eq!((frames[0].number, frames[0].time), (2, 0.1));
        let turntable = AnimationArgs {
            frames: None,
            fps: 24.0,
            turntable: Some(4),
        };
        let turns: Vec<_> = turntable
            .frames()
            .unwrap()
            .unwrap()
            .iter()
            .map(|f| f.turns)
            .collect();
        assert_eq!(turns, [Some(0.0), Some(0.25), Some(0.5), Some(0.75)]);
        assert!(AnimationArgs::default().frames().is_err(), "fps 0");
        assert_eq!(
            numbered(Path::new("out/shot.exr"), 12),
            PathBuf::from("out/shot.0012.exr")
        );
    }
}
