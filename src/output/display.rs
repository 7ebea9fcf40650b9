//! A live view of the image as it converges, in the tev viewer, over tev's TCP protocol
//! (tev's `include/tev/Ipc.h`; pbrt-v4's `--display-server` speaks the same): each packet
//! is a little-endian u32 byte count (itself included), a one-byte type, then fields —
//! strings NUL-terminated, integers and floats little-endian. gridtrace sends one
//! `CreateImage` (type 4) with channels R, G, B, A, then `UpdateImageV3` (type 6) bands of
//! rows with interleaved channels (offsets 0–3, stride 4).
//!
//! The viewer is a convenience: if it cannot be reached or goes away, the render goes on
//! without it (one warning), and a stalled viewer delays a pass by at most the write
//! timeout once.

use std::io::{self, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

use crate::render::Image;

/// tev's packet type of `CreateImage`.
pub const CREATE_IMAGE: u8 = 4;
/// tev's packet type of `UpdateImageV3` (channel offsets and strides).
pub const UPDATE_IMAGE_V3: u8 = 6;

/// Longest a connection attempt or a write may take before the viewer is given up.
const TIMEOUT: Duration = Duration::from_secs(5);

/// Least time between two updates of the view during a render.
const MIN_INTERVAL: Duration = Duration::from_millis(250);

/// Most pixel bytes in one update packet (tev buffers whole packets).
const BAND_BYTES: usize = 1 << 22;

/// A connection to a tev viewer, or none once it has gone away.
pub struct LiveView {
    stream: Option<TcpStream>,
    name: String,
    last: Option<Instant>,
}

/// A tev packet under construction.
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8) -> Packet {
        let mut bytes = vec![0u8; 4];
        bytes.push(kind);
        Packet(bytes)
    }

    fn flag(mut self, value: bool) -> Packet {
        self.0.push(u8::from(value));
        self
    }

    fn text(mut self, value: &str) -> Packet {
        // A NUL inside a name would end it early; tev names never need one.
        self.0.extend(value.bytes().filter(|&b| b != 0));
        self.0.push(0);
        self
    }

    fn int(mut self, value: i32) -> Packet {
        self.0.extend(value.to_le_bytes());
        self
    }

    fn long(mut self, value: i64) -> Packet {
        self.0.extend(value.to_le_bytes());
        self
    }

    fn floats(mut self, values: impl Iterator<Item = f32>) -> Packet {
        for v in values {
            self.0.extend(v.to_le_bytes());
        }
        self
    }

    fn finish(mut self) -> Vec<u8> {
        let size = u32::try_from(self.0.len()).unwrap_or(u32::MAX);
        self.0[..4].copy_from_slice(&size.to_le_bytes());
        self.0
    }
}

/// The channels gridtrace shows.
const CHANNELS: [&str; 4] = ["R", "G", "B", "A"];

/// The `CreateImage` packet for an image called `name`.
pub fn create_image_packet(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut packet = Packet::new(CREATE_IMAGE)
        .flag(true)
        .text(name)
        .int(width as i32)
        .int(height as i32)
        .int(CHANNELS.len() as i32);
    for channel in CHANNELS {
        packet = packet.text(channel);
    }
    packet.finish()
}

/// `UpdateImageV3` packets covering `image`, in bands of rows.
pub fn update_image_packets(name: &str, image: &Image) -> Vec<Vec<u8>> {
    let width = image.width as usize;
    let rows_per_band = (BAND_BYTES / (16 * width.max(1))).max(1);
    (0..image.height as usize)
        .step_by(rows_per_band)
        .map(|y0| {
            let rows = rows_per_band.min(image.height as usize - y0);
            let mut packet = Packet::new(UPDATE_IMAGE_V3)
                .flag(false)
                .text(name)
                .int(CHANNELS.len() as i32);
            for channel in CHANNELS {
                packet = packet.text(channel);
            }
            packet = packet
                .int(0)
                .int(y0 as i32)
                .int(width as i32)
                .int(rows as i32);
            for offset in 0..CHANNELS.len() as i64 {
                packet = packet.long(offset);
            }
            for _ in CHANNELS {
                packet = packet.long(CHANNELS.len() as i64);
            }
            let range = y0 * width..(y0 + rows) * width;
            packet
                .floats(range.flat_map(|i| {
                    let p = image.pixels[i];
                    [p.x, p.y, p.z, image.alpha[i]]
                }))
                .finish()
        })
        .collect()
}

impl LiveView {
    /// Connects to tev at `address` (HOST:PORT) and creates the image `gridtrace: NAME`.
    pub fn connect(address: &str, name: &str, width: u32, height: u32) -> io::Result<LiveView> {
        let target = address.to_socket_addrs()?.next().ok_or_else(|| {
            io::Error::new(io::ErrorKind::NotFound, "the address resolves to nothing")
        })?;
        let mut stream = TcpStream::connect_timeout(&target, TIMEOUT)?;
        stream.set_write_timeout(Some(TIMEOUT))?;
        stream.set_nodelay(true)?;
        let name = format!("gridtrace: {name}");
        stream.write_all(&create_image_packet(&name, width, height))?;
        Ok(LiveView {
            stream: Some(stream),
            name,
            last: None,
        })
    }

    /// A view with no viewer.
    pub fn disconnected() -> LiveView {
        LiveView {
            stream: None,
            name: String::new(),
            last: None,
        }
    }

    /// True when connected and the last update is old enough for another.
    pub fn wants_update(&self) -> bool {
        self.stream.is_some() && self.last.is_none_or(|t| t.elapsed() >= MIN_INTERVAL)
    }

    /// Sends the image; on failure warns once and carries on without the viewer.
    pub fn show(&mut self, image: &Image) {
        let Some(stream) = &mut self.stream else {
            return;
        };
        let sent = update_image_packets(&self.name, image)
            .iter()
            .try_for_each(|packet| stream.write_all(packet));
        if let Err(e) = sent {
            crate::terminal::say(format_args!(
                "warning: the live view was lost ({e}); rendering goes on"
            ));
            self.stream = None;
        }
        self.last = Some(Instant::now());
    }
}
