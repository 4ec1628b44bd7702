//! Which denoiser runs: Intel Open Image Denoise where it loads (`crate::oidn`), else rt's own
//! À-Trous filter (`crate::denoise`). `rt-cli render/merge/converge --denoise`, the editor's
//! denoised view and the live viewport all come through `denoise_with`, and say which one ran.

use crate::denoise::{DenoiseInput, DenoiseParams, denoise};
use crate::oidn::{Oidn, OidnInput};

/// What the user asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DenoiserChoice {
    /// OIDN when it loads, else À-Trous (saying why).
    #[default]
    Auto,
    /// OIDN or an error.
    Oidn,
    Atrous,
}

impl DenoiserChoice {
    pub const NAMES: [&'static str; 3] = ["auto", "oidn", "atrous"];

    pub fn parse(name: &str) -> Result<Self, String> {
        match name.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(DenoiserChoice::Auto),
            "oidn" => Ok(DenoiserChoice::Oidn),
            "atrous" | "à-trous" | "a-trous" => Ok(DenoiserChoice::Atrous),
            other => Err(format!(
                "unknown denoiser '{other}' (use one of: {})",
                Self::NAMES.join(", ")
            )),
        }
    }
}

/// What ran.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Denoiser {
    Oidn,
    Atrous,
}

impl Denoiser {
    pub fn name(self) -> &'static str {
        match self {
            Denoiser::Oidn => "Open Image Denoise",
            Denoiser::Atrous => "À-Trous",
        }
    }
}

/// A denoised image and where it came from.
#[derive(Clone, Debug)]
pub struct Denoised {
    pub pixels: Vec<[f32; 3]>,
    pub denoiser: Denoiser,
    /// Why OIDN did not run when `Auto` fell back to À-Trous.
    pub fallback: Option<String>,
}

/// Denoises `input` with the chosen denoiser. OIDN filters the whole colour (light seen directly
/// included) guided by albedo and normal; À-Trous filters the lighting and keeps `emission` and
/// `variance` as its module says.
pub fn denoise_with(choice: DenoiserChoice, input: &DenoiseInput) -> Result<Denoised, String> {
    denoise_limited(choice, input, None, &|| true)
}

/// As `denoise_with`, with OIDN on at most `threads` threads (À-Trous runs on one) and stopped
/// (`crate::oidn::CANCELLED`, no fallback) once `keep_going` says no: the live viewport's denoise
/// of an image a change has made stale.
pub fn denoise_limited(
    choice: DenoiserChoice,
    input: &DenoiseInput,
    threads: Option<u32>,
    keep_going: &(dyn Fn() -> bool + Sync),
) -> Result<Denoised, String> {
    let oidn = match choice {
        DenoiserChoice::Atrous => Err(String::new()),
        DenoiserChoice::Oidn => Ok(Oidn::get()?),
        DenoiserChoice::Auto => Oidn::get(),
    };
    let fallback = match oidn {
        Ok(oidn) => match oidn.denoise(
            &OidnInput {
                width: input.width,
                height: input.height,
                color: input.color,
                albedo: input.albedo,
                normal: input.normal,
            },
            threads,
            keep_going,
        ) {
            Ok(pixels) => {
                return Ok(Denoised {
                    pixels,
                    denoiser: Denoiser::Oidn,
                    fallback: None,
                });
            }
            Err(e) if choice == DenoiserChoice::Oidn || e == crate::oidn::CANCELLED => {
                return Err(e);
            }
            Err(e) => Some(e),
        },
        Err(e) if e.is_empty() => None,
        Err(e) => Some(e),
    };
    if let Some(why) = &fallback {
        log::info!("denoising with À-Trous: {why}");
    }
    Ok(Denoised {
        pixels: denoise(input, &DenoiseParams::default())?,
        denoiser: Denoiser::Atrous,
        fallback,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_parse_and_unknown_ones_name_the_options() {
        assert_eq!(DenoiserChoice::parse("OIDN"), Ok(DenoiserChoice::Oidn));
        assert_eq!(DenoiserChoice::parse("atrous"), Ok(DenoiserChoice::Atrous));
        let e = DenoiserChoice::parse("nlm").unwrap_err();
        assert!(e.contains("auto, oidn, atrous"), "{e}");
    }

    #[test]
    fn atrous_is_used_when_asked_for() {
        let px = vec![[0.5f32; 3]; 16];
        let zero = vec![[0.0f32; 3]; 16];
        let variance = vec![0.0f32; 16];
        let out = denoise_with(
            DenoiserChoice::Atrous,
            &DenoiseInput {
                width: 4,
                height: 4,
                color: &px,
                emission: &zero,
                albedo: &px,
                normal: &px,
                variance: &variance,
            },
        )
        .unwrap();
        assert_eq!(out.denoiser, Denoiser::Atrous);
        assert!(out.fallback.is_none());
    }
}
