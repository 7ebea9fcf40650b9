//! What produced a rendered image: gridtrace's version, the SHA-256 of the scene and of the
//! files it reads, the camera, size, seed and settings, and which samples of every pixel it
//! holds. Every EXR gridtrace writes carries this record in its header, so images rendered
//! apart — on other machines, at other times — can be checked and merged ([`crate::output::merge`]).
//!
//! The record is one text attribute, [`RECORD_ATTRIBUTE`], of `key=value` lines: the `exr`
//! crate writes a header's attributes in hash-map order, so one attribute keeps the file's
//! bytes the same from run to run.

use std::fmt;
use std::io;
use std::ops::Range;
use std::path::Path;

use sha2::{Digest, Sha256};

/// The EXR header attribute holding the record.
pub const RECORD_ATTRIBUTE: &str = "gridtrace/record";

/// The provenance of one rendered image.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderRecord {
    /// The identity of the render: two images are parts of the same render when equal.
    pub identity: RenderIdentity,
    /// The scene file's name, for messages (its path may differ from machine to machine).
    pub scene_name: String,
    /// The sample indices every pixel holds.
    pub samples: Range<u32>,
    /// Samples that came out NaN or infinite and were counted as black.
    pub nonfinite: u64,
    /// `--noise-threshold` of an adaptive render, whose pixels hold different numbers of
    /// samples (the `samples.N` layer): such images are not parts that merge.
    pub noise_threshold: Option<f32>,
    /// True when the beauty was denoised (the noisy one is the `noisy` layer).
    pub denoised: bool,
}

/// Everything that decides which value a given sample of a given pixel takes. Parts with the
/// same identity and disjoint sample ranges add up to one render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderIdentity {
    /// gridtrace's version: another version may trace the same sample differently.
    pub version: String,
    /// SHA-256 of the scene file's bytes, as `sha256sum` prints it.
    pub scene_sha256: String,
    /// SHA-256 over the other files the scene was read from ([`sha256_files`]).
    pub dependencies_sha256: String,
    /// The camera's name and where it came from.
    pub camera: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The random seed.
    pub seed: u64,
    /// Most scattering events along a path.
    pub max_depth: u32,
    /// Every other option that changes a sample's value, as text: how the scene was read
    /// (glTF light units, frame, animation, subdivision), the shutter, the environment and
    /// the pixel filter. Kept under the key `loadOptions`, which files already written use.
    pub options: String,
    /// `--exposure` in stops, applied to every output: parts merge only at equal exposure.
    pub exposure: f32,
    /// The auxiliary layers kept (`--aov`), comma-separated: parts merge only with the
    /// same layers.
    pub aovs: String,
}

/// Why a header does not hold a record.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RecordError {
    /// The header has no record at all.
    #[error("its header has no '{RECORD_ATTRIBUTE}' attribute")]
    NoRecord,
    /// A field the record needs is absent.
    #[error("the '{RECORD_ATTRIBUTE}' header attribute has no '{0}' line")]
    Missing(&'static str),
    /// A field is there but does not parse.
    #[error(
        "in the '{RECORD_ATTRIBUTE}' header attribute, {key} is '{value}', which is not {expected}"
    )]
    Malformed {
        /// The field's name.
        key: &'static str,
        /// Its text.
        value: String,
        /// What it should have been.
        expected: &'static str,
    },
}

impl RenderIdentity {
    /// The first field in which `self` and `other` differ: (name, ours, theirs).
    pub fn difference(&self, other: &RenderIdentity) -> Option<(&'static str, String, String)> {
        let ours = self.fields();
        let theirs = other.fields();
        ours.into_iter()
            .zip(theirs)
            .find(|(a, b)| a.1 != b.1)
            .map(|(a, b)| (a.0, a.1, b.1))
    }

    /// The identity as (attribute name, text) pairs, in a fixed order.
    fn fields(&self) -> [(&'static str, String); 11] {
        [
            ("version", self.version.clone()),
            ("sceneSha256", self.scene_sha256.clone()),
            ("dependenciesSha256", self.dependencies_sha256.clone()),
            ("camera", self.camera.clone()),
            ("width", self.width.to_string()),
            ("height", self.height.to_string()),
            ("seed", self.seed.to_string()),
            ("maxDepth", self.max_depth.to_string()),
            ("loadOptions", self.options.clone()),
            ("exposure", self.exposure.to_string()),
            ("aovs", self.aovs.clone()),
        ]
    }
}

impl RenderRecord {
    /// The record as the text of [`RECORD_ATTRIBUTE`]: one `key=value` line per field,
    /// with backslashes and line breaks in values escaped.
    pub fn to_text(&self) -> String {
        let mut fields: Vec<(&str, String)> = self.identity.fields().into();
        fields.push(("scene", self.scene_name.clone()));
        fields.push(("samples", format_range(&self.samples)));
        fields.push(("nonfinite", self.nonfinite.to_string()));
        if let Some(t) = self.noise_threshold {
            fields.push(("noiseThreshold", t.to_string()));
        }
        if self.denoised {
            fields.push(("denoised", "true".into()));
        }
        fields
            .into_iter()
            .map(|(k, v)| format!("{k}={}\n", escape(&v)))
            .collect()
    }

    /// The record in the text of [`RECORD_ATTRIBUTE`]; unknown keys are ignored, so later
    /// versions may add fields.
    pub fn from_text(record: &str) -> Result<RenderRecord, RecordError> {
        let fields: Vec<(&str, String)> = record
            .lines()
            .filter_map(|line| line.split_once('='))
            .map(|(k, v)| (k, unescape(v)))
            .collect();
        let text = |key: &'static str| {
            fields
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, v)| v.clone())
                .ok_or(RecordError::Missing(key))
        };
        let number = |key: &'static str| -> Result<u64, RecordError> {
            let value = text(key)?;
            value.parse().map_err(|_| RecordError::Malformed {
                key,
                value,
                expected: "a whole number",
            })
        };
        let small = |key: &'static str| -> Result<u32, RecordError> {
            let value = number(key)?;
            u32::try_from(value).map_err(|_| RecordError::Malformed {
                key,
                value: value.to_string(),
                expected: "a number below 2^32",
            })
        };
        let samples_text = text("samples")?;
        let samples = parse_range(&samples_text).map_err(|_| RecordError::Malformed {
            key: "samples",
            value: samples_text.clone(),
            expected: "a sample range A..B with A < B",
        })?;
        Ok(RenderRecord {
            identity: RenderIdentity {
                version: text("version")?,
                scene_sha256: text("sceneSha256")?,
                dependencies_sha256: text("dependenciesSha256")?,
                camera: text("camera")?,
                width: small("width")?,
                height: small("height")?,
                seed: number("seed")?,
                max_depth: small("maxDepth")?,
                options: text("loadOptions")?,
                // Records from before --exposure had none: 0 stops.
                exposure: match text("exposure") {
                    Err(_) => 0.0,
                    Ok(value) => value.parse::<f32>().ok().filter(|v| v.is_finite()).ok_or(
                        RecordError::Malformed {
                            key: "exposure",
                            value,
                            expected: "a number of stops",
                        },
                    )?,
                },
                // Records from before --aov had no layers.
                aovs: text("aovs").unwrap_or_default(),
            },
            scene_name: text("scene")?,
            samples,
            nonfinite: number("nonfinite")?,
            noise_threshold: match text("noiseThreshold") {
                Err(_) => None,
                Ok(value) => Some(value.parse::<f32>().ok().filter(|v| *v > 0.0).ok_or(
                    RecordError::Malformed {
                        key: "noiseThreshold",
                        value,
                        expected: "a positive number",
                    },
                )?),
            },
            denoised: text("denoised").is_ok_and(|v| v == "true"),
        })
    }
}

/// A value on one line: `\` becomes `\\`, a line break `\n` (or `\r`).
fn escape(value: &str) -> String {
    value
        .replace('\\', "\\\\")
        .replace('\n', "\\n")
        .replace('\r', "\\r")
}

/// The inverse of [`escape`].
fn unescape(value: &str) -> String {
    let mut out = String::with_capacity(value.len());
    let mut chars = value.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('r') => out.push('\r'),
            Some(other) => out.push(other),
            None => out.push('\\'),
        }
    }
    out
}

/// A sample range as the command line writes it: `A..B`.
pub fn format_range(range: &Range<u32>) -> String {
    format!("{}..{}", range.start, range.end)
}

/// Parses `A..B` (whole numbers, A < B): samples A to B − 1.
pub fn parse_range(text: &str) -> Result<Range<u32>, String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("'{text}' is not a range A..B (for example 0..64)"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{s}' in '{text}' is not a whole number below 2^32"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a >= b {
        return Err(format!(
            "'{text}' is empty: the end must be above the start"
        ));
    }
    Ok(a..b)
}

/// SHA-256 of a file's bytes, in lowercase hex as `sha256sum` prints it.
pub fn sha256_file(path: &Path) -> io::Result<String> {
    let mut hasher = Sha256::new();
    io::copy(&mut std::fs::File::open(path)?, &mut hasher)?;
    Ok(Hex(&hasher.finalize()).to_string())
}

/// A file a scene was read from besides the scene file itself.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Dependency {
    /// Where it is.
    pub path: std::path::PathBuf,
    /// How many of its first bytes were read, if not all (a glTF buffer reads its
    /// `byteLength`): only those are hashed, so a huge file behind a small buffer costs
    /// nothing.
    pub bytes_read: Option<u64>,
}

impl Dependency {
    /// A file read whole.
    pub fn whole(path: std::path::PathBuf) -> Dependency {
        Dependency {
            path,
            bytes_read: None,
        }
    }
}

/// One SHA-256 for a set of files: of the lines `NAME<TAB>SHA256`, sorted, where NAME is
/// the path relative to `base` (the scene's folder) when it lies inside, so the same files
/// mounted elsewhere on another machine hash the same, and SHA256 is of the bytes read.
pub fn sha256_files(base: &Path, files: &[Dependency]) -> io::Result<String> {
    let base = base.canonicalize()?;
    let mut lines = files
        .iter()
        .map(|dependency| {
            let file = dependency.path.canonicalize()?;
            let name = file.strip_prefix(&base).unwrap_or(&file);
            let mut hasher = Sha256::new();
            let reader = io::Read::take(
                std::fs::File::open(&file)?,
                dependency.bytes_read.unwrap_or(u64::MAX),
            );
            io::copy(&mut { reader }, &mut hasher)?;
            let hash = Hex(&hasher.finalize()).to_string();
            Ok(format!("{}\t{hash}\n", name.display()))
        })
        .collect::<io::Result<Vec<String>>>()?;
    lines.sort();
    Ok(Hex(&Sha256::digest(lines.concat().as_bytes())).to_string())
}

/// Bytes as lowercase hex.
struct Hex<'a>(&'a [u8]);

impl fmt::Display for Hex<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|b| write!(f, "{b:02x}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> RenderRecord {
        RenderRecord {
            identity: RenderIdentity {
                version: "1.2.3".into(),
                scene_sha256: "ab".repeat(32),
                dependencies_sha256: "cd".repeat(32),
                camera: "'Kamera \\ \"ü\"\nzwei' (glTF node 3)".into(),
                width: 640,
                height: 480,
                seed: u64::MAX,
                max_depth: 16,
                options: "gltf-light-units=standard".into(),
                exposure: -1.5,
                aovs: "albedo,normal".into(),
            },
            scene_name: "box.glb".into(),
            samples: 64..128,
            nonfinite: 2,
            noise_threshold: None,
            denoised: false,
        }
    }

    #[test]
    fn a_record_survives_its_text() {
        let record = record();
        let text = record.to_text();
        assert_eq!(text.lines().count(), 14, "one line per field:\n{text}");
        assert_eq!(RenderRecord::from_text(&text), Ok(record.clone()));
        let mut adaptive = record.clone();
        adaptive.noise_threshold = Some(0.02);
        adaptive.denoised = true;
        assert_eq!(RenderRecord::from_text(&adaptive.to_text()), Ok(adaptive));
        // Records from before --exposure read as 0 stops.
        let old: String = text
            .lines()
            .filter(|l| !l.starts_with("exposure="))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(
            RenderRecord::from_text(&old).unwrap().identity.exposure,
            0.0
        );
    }

    #[test]
    fn a_missing_or_malformed_field_is_named() {
        let text = record().to_text();
        let bad_range = text.replace("samples=64..128", "samples=9..3");
        let err = RenderRecord::from_text(&bad_range).unwrap_err();
        assert!(
            err.to_string().contains("samples") && err.to_string().contains("9..3"),
            "{err}"
        );
        let no_seed: String = text
            .lines()
            .filter(|l| !l.starts_with("seed="))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(
            RenderRecord::from_text(&no_seed),
            Err(RecordError::Missing("seed"))
        );
    }

    #[test]
    fn identities_name_their_first_difference() {
        let a = record().identity;
        let mut b = a.clone();
        assert_eq!(a.difference(&b), None);
        b.seed = 7;
        assert_eq!(
            a.difference(&b),
            Some(("seed", u64::MAX.to_string(), "7".to_string()))
        );
    }

    #[test]
    fn ranges_parse_as_written() {
        assert_eq!(parse_range("0..64"), Ok(0..64));
        assert_eq!(parse_range(" 5 .. 6"), Ok(5..6));
        for bad in ["64", "3..3", "4..2", "a..b", "-1..4", "0..4294967296"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
        assert_eq!(format_range(&(3..9)), "3..9");
    }

    #[test]
    fn a_set_of_files_hashes_by_name_and_content_wherever_it_lies() {
        let hash_in = |dir: &Path, content: &[u8]| {
            std::fs::create_dir_all(dir.join("textures")).unwrap();
            std::fs::write(dir.join("scene.bin"), b"buffer").unwrap();
            std::fs::write(dir.join("textures/wood.png"), content).unwrap();
            let files = [dir.join("textures/wood.png"), dir.join("scene.bin")];
            sha256_files(dir, &files.map(Dependency::whole)).unwrap()
        };
        let root = tempfile::tempdir().unwrap();
        let here = hash_in(&root.path().join("a"), b"wood");
        assert_eq!(here, hash_in(&root.path().join("b/elsewhere"), b"wood"));
        assert_ne!(here, hash_in(&root.path().join("c"), b"oak"));
        let missing = Dependency::whole(root.path().join("missing"));
        assert!(sha256_files(root.path(), &[missing]).is_err());
        // Only the bytes read count: what lies past a buffer's byteLength does not.
        let dir = root.path().join("a");
        let head = |bytes: &[u8]| {
            std::fs::write(dir.join("scene.bin"), bytes).unwrap();
            let buffer = Dependency {
                path: dir.join("scene.bin"),
                bytes_read: Some(6),
            };
            sha256_files(&dir, &[buffer]).unwrap()
        };
        assert_eq!(head(b"buffer and more"), head(b"buffer"));
        assert_ne!(head(b"buffer"), head(b"BUFFER"));
    }

    #[test]
    fn the_hash_is_sha256() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("abc");
        std::fs::write(&path, b"abc").unwrap();
        // FIPS 180-2, appendix B.1.
        assert_eq!(
            sha256_file(&path).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
