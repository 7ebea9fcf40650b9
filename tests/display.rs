//! The live view: a fake tev server decodes what `--display` sends (tev's IPC protocol) and
//! finds the image gridtrace wrote; a viewer that goes away does not stop the render.

#[path = "support/binary/mod.rs"]
mod binary;

use std::io::Read;
use std::net::TcpListener;
use std::path::Path;
use std::thread;

use gridtrace::output::display::{CREATE_IMAGE, UPDATE_IMAGE_V3};
use gridtrace::output::read_exr_pixels;

/// A little-endian reader over one packet's fields.
struct Fields<'a>(&'a [u8]);

impl Fields<'_> {
    fn byte(&mut self) -> u8 {
        let b = self.0[0];
        self.0 = &self.0[1..];
        b
    }
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let bytes = self.0[..N].try_into().unwrap();
        self.0 = &self.0[N..];
        bytes
    }
    fn int(&mut self) -> i32 {
        i32::from_le_bytes(self.take())
    }
    fn long(&mut self) -> i64 {
        i64::from_le_bytes(self.take())
    }
    fn float(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }
    fn text(&mut self) -> String {
        let end = self.0.iter().position(|&b| b == 0).unwrap();
        let s = String::from_utf8(self.0[..end].to_vec()).unwrap();
        self.0 = &self.0[end + 1..];
        s
    }
}

/// What the fake viewer saw: the created image (name, width, height, channels) and the
/// image as updated, RGBA per pixel.
#[derive(Default)]
struct Seen {
    created: Option<(String, i32, i32, Vec<String>)>,
    updates: usize,
    pixels: Vec<[f32; 4]>,
}

/// Decodes a stream of tev packets.
fn decode(stream: &[u8]) -> Seen {
    let mut seen = Seen::default();
    let mut rest = stream;
    while !rest.is_empty() {
        let size = u32::from_le_bytes(rest[..4].try_into().unwrap()) as usize;
        let mut f = Fields(&rest[4..size]);
        rest = &rest[size..];
        match f.byte() {
            CREATE_IMAGE => {
                assert_eq!(f.byte(), 1, "grab focus");
                let name = f.text();
                let (w, h, n) = (f.int(), f.int(), f.int());
                let channels = (0..n).map(|_| f.text()).collect();
                seen.pixels = vec![[f32::NAN; 4]; (w * h) as usize];
                seen.created = Some((name, w, h, channels));
            }
            UPDATE_IMAGE_V3 => {
                let (_, width, _, _) = seen.created.clone().expect("CreateImage first");
                f.byte();
                let _name = f.text();
                let n = f.int() as usize;
                let channels: Vec<String> = (0..n).map(|_| f.text()).collect();
                assert_eq!(channels, ["R", "G", "B", "A"]);
                let (x, y, w, h) = (f.int(), f.int(), f.int(), f.int());
                let offsets: Vec<i64> = (0..n).map(|_| f.long()).collect();
                let strides: Vec<i64> = (0..n).map(|_| f.long()).collect();
                let data: Vec<f32> =
                    std::iter::from_fn(|| (!f.0.is_empty()).then(|| f.float())).collect();
                for py in 0..h {
                    for px in 0..w {
                        let k = (py * w + px) as i64;
                        let target = ((y + py) * width + x + px) as usize;
                        for c in 0..n {
                            seen.pixels[target][c] = data[(offsets[c] + k * strides[c]) as usize];
                        }
                    }
                }
                seen.updates += 1;
            }
            other => panic!("unexpected packet type {other}"),
        }
    }
    seen
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/cornell_box.glb")
        .display()
        .to_string()
}

#[test]
fn the_viewer_is_shown_the_image_that_is_written() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let server = thread::spawn(move || {
        let (mut stream, _) = listener.accept().unwrap();
        let mut bytes = Vec::new();
        stream.read_to_end(&mut bytes).unwrap();
        bytes
    });
    let dir = tempfile::tempdir().unwrap();
    let out = binary::gridtrace(
        &[
            &scene(),
            "--width",
            "20",
            "--height",
            "12",
            "--spp",
            "6",
            "--display",
            &address,
            "-o",
            "shown.exr",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", binary::stderr(&out));
    let seen = decode(&server.join().unwrap());
    let (name, w, h, channels) = seen.created.unwrap();
    assert_eq!(
        (name.as_str(), w, h),
        ("gridtrace: cornell_box.glb", 20, 12)
    );
    assert_eq!(channels, ["R", "G", "B", "A"]);
    assert!(seen.updates >= 2, "{} updates", seen.updates);
    let written = read_exr_pixels(&dir.path().join("shown.exr")).unwrap();
    for (i, shown) in seen.pixels.iter().enumerate() {
        let p = written.rgb[i];
        assert_eq!(*shown, [p.x, p.y, p.z, written.alpha[i]], "pixel {i}");
    }
}

#[test]
fn a_render_that_loses_its_viewer_keeps_rendering() {
    // A viewer that accepts and hangs up at once.
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let server = thread::spawn(move || drop(listener.accept().unwrap()));
    let dir = tempfile::tempdir().unwrap();
    let render = |address: &str, output: &str| {
        binary::gridtrace(
            &[
                &scene(),
                "--width",
                "64",
                "--spp",
                "32",
                "--display",
                address,
                "-o",
                output,
            ],
            dir.path(),
        )
    };
    let out = render(&address, "lost.exr");
    server.join().unwrap();
    assert!(out.status.success(), "{}", binary::stderr(&out));
    assert!(dir.path().join("lost.exr").exists());
    // No viewer at all: a warning, and the render.
    let closed = TcpListener::bind("127.0.0.1:0").unwrap();
    let nobody = closed.local_addr().unwrap().to_string();
    drop(closed);
    let out = render(&nobody, "alone.exr");
    let stderr = binary::stderr(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("rendering without a live view"), "{stderr}");
    assert!(dir.path().join("alone.exr").exists());
}
