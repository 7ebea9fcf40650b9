//! A live view of the image as it converges, in the tev viewer, over tev's TCP protocol
//! (tev's `include/tev/Ipc.h`; pbrt-v4's `--display-server` speaks the same): each packet
//! is a little-endian u32 byte count (itself included), a one-byte type, then fields —
//! strings NUL-terminated, integers and floats little-endian. gridtrace sends one
//! `CreateImage` (type 4) with channels R, G, B, A, then `UpdateImageV3` (type 6) bands of
//! rows with interleaved channels (offsets 0–3, stride 4).
//!
//! The viewer is a convenience and never holds up a render: a thread of its own connects
//! and sends, the render hands it the latest image and goes on (a frame not yet sent is
//! replaced by the newer one), each update must be sent within a deadline or the viewer is
//! given up (one warning), and the final image waits for the viewer only briefly, after
//! the output has been written.

use std::io::{self, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::render::Image;

/// tev's packet type of `CreateImage`.
pub const CREATE_IMAGE: u8 = 4;
/// tev's packet type of `UpdateImageV3` (channel offsets and strides).
pub const UPDATE_IMAGE_V3: u8 = 6;

/// Longest a connection attempt, or the sending of one whole update, may take before the
/// viewer is given up.
const DEADLINE: Duration = Duration::from_secs(5);

/// Bytes written between two looks at the deadline.
const CHUNK: usize = 1 << 16;

/// Least time between two updates of the view during a render.
const MIN_INTERVAL: Duration = Duration::from_millis(250);

/// Most pixel bytes in one update packet (tev buffers whole packets).
const BAND_BYTES: usize = 1 << 22;

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

/// The pixels a viewer is sent: RGBA, row by row.
pub struct Frame {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Red, green, blue and alpha of each pixel, row by row from the top.
    pub rgba: Vec<[f32; 4]>,
}

impl Frame {
    /// The colour and alpha of `image`.
    pub fn of(image: &Image) -> Frame {
        Frame {
            width: image.width,
            height: image.height,
            rgba: image
                .pixels
                .iter()
                .zip(&image.alpha)
                .map(|(p, &a)| [p.x, p.y, p.z, a])
                .collect(),
        }
    }
}

/// `UpdateImageV3` packets covering `frame`, in bands of rows.
pub fn update_image_packets(name: &str, frame: &Frame) -> Vec<Vec<u8>> {
    let width = frame.width as usize;
    let rows_per_band = (BAND_BYTES / (16 * width.max(1))).max(1);
    (0..frame.height as usize)
        .step_by(rows_per_band)
        .map(|y0| {
            let rows = rows_per_band.min(frame.height as usize - y0);
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
                .floats(frame.rgba[range].iter().flatten().copied())
                .finish()
        })
        .collect()
}

/// What the render and the sending thread share.
#[derive(Default)]
struct Mailbox {
    /// The newest frame not yet taken by the sender.
    next: Option<Frame>,
    /// No more frames will come.
    closed: bool,
    /// The sender has ended (viewer lost, never reached, or all sent).
    ended: bool,
    /// When the sender began the update it is sending, if it is sending one.
    sending_since: Option<Instant>,
}

struct Shared {
    mailbox: Mutex<Mailbox>,
    changed: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Mailbox> {
        self.mailbox.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// A live view in tev, fed by a thread of its own.
pub struct LiveView {
    shared: Arc<Shared>,
    last: Option<Instant>,
}

impl LiveView {
    /// Starts a thread that connects to tev at `address` (HOST:PORT), creates the image
    /// `gridtrace: NAME` and sends the frames it is given; if the viewer cannot be reached
    /// or goes away, it warns once (naming `address`) and the render goes on without it.
    pub fn start(address: &str, name: &str, width: u32, height: u32) -> LiveView {
        let shared = Arc::new(Shared {
            mailbox: Mutex::new(Mailbox::default()),
            changed: Condvar::new(),
        });
        let (address, name) = (address.to_string(), format!("gridtrace: {name}"));
        let for_sender = Arc::clone(&shared);
        let started = std::thread::Builder::new()
            .name("live view".into())
            .spawn(move || {
                let outcome = Sender::connect(&address, &name, width, height)
                    .and_then(|mut sender| sender.run(&for_sender));
                if let Err(e) = outcome {
                    crate::terminal::say(format_args!(
                        "warning: --display {address}: {e}; rendering without a live view"
                    ));
                }
                for_sender.lock().ended = true;
                for_sender.changed.notify_all();
            });
        if started.is_err() {
            shared.lock().ended = true;
        }
        LiveView { shared, last: None }
    }

    /// True while the viewer is there and the last update is old enough for another.
    pub fn wants_update(&self) -> bool {
        !self.shared.lock().ended && self.last.is_none_or(|t| t.elapsed() >= MIN_INTERVAL)
    }

    /// Hands `image` to the sender, replacing a frame it has not taken yet.
    pub fn show(&mut self, image: &Image) {
        if self.shared.lock().ended {
            return;
        }
        let frame = Frame::of(image);
        self.shared.lock().next = Some(frame);
        self.shared.changed.notify_all();
        self.last = Some(Instant::now());
    }

    /// No more frames: waits at most `grace` for the sender to deliver the last one, and
    /// not at all for a viewer still taking an earlier update after [`MIN_INTERVAL`] (it
    /// would not see the last one in time anyway).
    pub fn finish(&mut self, grace: Duration) {
        let until = Instant::now() + grace;
        let mut mailbox = self.shared.lock();
        mailbox.closed = true;
        self.shared.changed.notify_all();
        if mailbox
            .sending_since
            .is_some_and(|t| t.elapsed() >= MIN_INTERVAL)
        {
            return;
        }
        while !mailbox.ended {
            let left = until.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return;
            }
            mailbox = self
                .shared
                .changed
                .wait_timeout(mailbox, left)
                .unwrap_or_else(|p| p.into_inner())
                .0;
        }
    }
}

/// The connection, owned by the sending thread.
struct Sender {
    stream: TcpStream,
    name: String,
}

impl Sender {
    fn connect(address: &str, name: &str, width: u32, height: u32) -> io::Result<Sender> {
        let target = address.to_socket_addrs()?.next().ok_or_else(|| {
            io::Error::new(io::ErrorKind::NotFound, "the address resolves to nothing")
        })?;
        let stream = TcpStream::connect_timeout(&target, DEADLINE)?;
        stream.set_nodelay(true)?;
        let mut sender = Sender {
            stream,
            name: name.to_string(),
        };
        sender.send(&[create_image_packet(name, width, height)])?;
        Ok(sender)
    }

    /// Sends frames as they come until the view is closed and the last one is sent.
    fn run(&mut self, shared: &Shared) -> io::Result<()> {
        loop {
            let frame = {
                let mut mailbox = shared.lock();
                mailbox.sending_since = None;
                loop {
                    if let Some(frame) = mailbox.next.take() {
                        mailbox.sending_since = Some(Instant::now());
                        break frame;
                    }
                    if mailbox.closed {
                        return Ok(());
                    }
                    mailbox = shared
                        .changed
                        .wait(mailbox)
                        .unwrap_or_else(|p| p.into_inner());
                }
            };
            self.send(&update_image_packets(&self.name, &frame))
                .map_err(|e| io::Error::new(e.kind(), format!("the live view was lost ({e})")))?;
        }
    }

    /// Writes `packets` within [`DEADLINE`] in all, however slowly the viewer reads.
    fn send(&mut self, packets: &[Vec<u8>]) -> io::Result<()> {
        let until = Instant::now() + DEADLINE;
        for chunk in packets.iter().flat_map(|p| p.chunks(CHUNK)) {
            let mut rest = chunk;
            while !rest.is_empty() {
                let left = until.saturating_duration_since(Instant::now());
                if left.is_zero() {
                    return Err(io::Error::new(
                        io::ErrorKind::TimedOut,
                        format!(
                            "an update took longer than {} s to send",
                            DEADLINE.as_secs()
                        ),
                    ));
                }
                self.stream.set_write_timeout(Some(left))?;
                match self.stream.write(rest) {
                    Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                    Ok(n) => rest = &rest[n..],
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    Err(e) => return Err(e),
                }
            }
        }
        Ok(())
    }
}
