//! `--display-server HOST:PORT`: the image streamed to the tev viewer while
//! it renders, as pbrt-v4 does (pbrt-v4 util/display.cpp; tev's IPC format).
//!
//! tev's packets, all little-endian: `u32` length of the whole packet (this
//! field included), `u8` type, then the payload; strings are NUL-terminated.
//! - create image (4): `u8` grab focus, name, `i32` width, height, channel
//!   count, then the channel names;
//! - update image (3): `u8` grab focus, name, channel name, `i32` x, y,
//!   width, height, then width × height `f32` (row-major) of that channel;
//! - close image (2): name.
//!
//! The socket lives on a thread of its own, fed through a bounded channel:
//! the renderer only ever `try_send`s tile updates (dropped if the viewer is
//! behind) and never waits on the network. Any socket error ends the thread;
//! the render goes on. The whole image is sent once more at the end so the
//! viewer ends with exactly the final image (updates dropped on the way, and
//! pixels near tile edges that later tiles' filter footprints changed). Like
//! pbrt-v4, the image is left open in the viewer when the render ends.

use crate::geometry::Bounds2i;
use crate::image::Image;
use std::io::Write;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::Duration;

/// Packet types (tev's `EType`).
pub const CLOSE_IMAGE: u8 = 2;
pub const UPDATE_IMAGE: u8 = 3;
pub const CREATE_IMAGE: u8 = 4;

/// RGB, as pbrt-v4 sends them.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// Largest side of one update (pbrt-v4 sends 128 × 128 tiles).
const MAX_UPDATE: i32 = 128;

/// Updates queued before further ones are dropped.
const QUEUE: usize = 64;

/// How long a write may block before the viewer is considered gone.
const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

fn put_str(out: &mut Vec<u8>, s: &str) {
    out.extend_from_slice(s.as_bytes());
    out.push(0);
}

fn finish(mut p: Vec<u8>) -> Vec<u8> {
    let n = p.len() as u32;
    p[..4].copy_from_slice(&n.to_le_bytes());
    p
}

fn start(kind: u8) -> Vec<u8> {
    let mut p = vec![0u8; 4];
    p.push(kind);
    p
}

/// The create-image packet.
pub fn create_packet(name: &str, width: i32, height: i32) -> Vec<u8> {
    let mut p = start(CREATE_IMAGE);
    p.push(1); // grab focus
    put_str(&mut p, name);
    for v in [width, height, CHANNELS.len() as i32] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for c in CHANNELS {
        put_str(&mut p, c);
    }
    finish(p)
}

/// One update-image packet: channel `c` of `rgb` (RGB triples of the
/// `w × h` rectangle at `x, y`).
pub fn update_packet(name: &str, c: usize, rect: [i32; 4], rgb: &[f32]) -> Vec<u8> {
    let mut p = start(UPDATE_IMAGE);
    p.reserve(rgb.len() / 3 * 4 + 64);
    p.push(0); // grab focus
    put_str(&mut p, name);
    put_str(&mut p, CHANNELS[c]);
    for v in rect {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for px in rgb.chunks_exact(3) {
        p.extend_from_slice(&px[c].to_le_bytes());
    }
    finish(p)
}

/// The close-image packet (not sent by pbrs: the finished image stays in
/// the viewer, as with pbrt-v4; kept for completeness of the protocol).
pub fn close_packet(name: &str) -> Vec<u8> {
    let mut p = start(CLOSE_IMAGE);
    put_str(&mut p, name);
    finish(p)
}

/// A rectangle of the image (relative to the image's top-left pixel) and its
/// RGB triples.
struct Update {
    rect: [i32; 4],
    rgb: Vec<f32>,
}

/// The client: a sending thread and the bounded queue that feeds it.
pub struct Display {
    tx: Option<SyncSender<Update>>,
    thread: Option<JoinHandle<Option<String>>>,
    /// The film's pixel-bounds origin: updates are relative to it.
    origin: (i32, i32),
    size: (i32, i32),
}

impl Display {
    /// Starts the client for an image of `pixel_bounds` named `name`. The
    /// connection is made on the client's thread; a failure is reported by
    /// [`Display::finish`].
    pub fn start(addr: &str, name: String, pixel_bounds: Bounds2i) -> Display {
        let size = (pixel_bounds.width(), pixel_bounds.height());
        let (tx, rx) = sync_channel::<Update>(QUEUE);
        let addr = addr.to_string();
        let thread = std::thread::Builder::new()
            .name("pbrs-display".into())
            .spawn(move || client(&addr, &name, size, rx).err())
            .ok();
        Display {
            tx: Some(tx),
            thread,
            origin: (pixel_bounds.min.x, pixel_bounds.min.y),
            size,
        }
    }

    /// Queues pixels of `region` (film pixel coordinates) unless the queue is
    /// full or the client has stopped: never blocks.
    pub fn offer(&mut self, region: Bounds2i, rgb: Vec<f32>) {
        let Some(tx) = &self.tx else { return };
        let rect = [
            region.min.x - self.origin.0,
            region.min.y - self.origin.1,
            region.width(),
            region.height(),
        ];
        if rect[2] <= 0 || rect[3] <= 0 {
            return;
        }
        match tx.try_send(Update { rect, rgb }) {
            Ok(()) | Err(TrySendError::Full(_)) => {}
            Err(TrySendError::Disconnected(_)) => self.tx = None,
        }
    }

    /// Sends the final image (waiting for queue space while the client
    /// lives), closes the connection and returns the client's error, if any.
    pub fn finish(mut self, image: &Image) -> Option<String> {
        if let Some(tx) = self.tx.take() {
            let (w, h) = self.size;
            'rows: for y0 in (0..h).step_by(MAX_UPDATE as usize) {
                for x0 in (0..w).step_by(MAX_UPDATE as usize) {
                    let (bw, bh) = ((w - x0).min(MAX_UPDATE), (h - y0).min(MAX_UPDATE));
                    let mut rgb = Vec::with_capacity((bw * bh * 3) as usize);
                    for y in y0..y0 + bh {
                        let i = 3 * (y as usize * image.width as usize + x0 as usize);
                        rgb.extend_from_slice(&image.data[i..i + 3 * bw as usize]);
                    }
                    let u = Update {
                        rect: [x0, y0, bw, bh],
                        rgb,
                    };
                    if tx.send(u).is_err() {
                        break 'rows;
                    }
                }
            }
        }
        self.thread.take().and_then(|t| t.join().ok().flatten())
    }
}

/// The client thread: connect, create the image, send updates until the
/// queue closes.
fn client(addr: &str, name: &str, size: (i32, i32), rx: Receiver<Update>) -> Result<(), String> {
    let fail = |e: std::io::Error| format!("display server {addr}: {e}");
    let sock = addr
        .to_socket_addrs()
        .map_err(fail)?
        .next()
        .ok_or_else(|| format!("display server {addr}: no address"))?;
    let mut s = TcpStream::connect_timeout(&sock, CONNECT_TIMEOUT).map_err(fail)?;
    s.set_write_timeout(Some(WRITE_TIMEOUT)).map_err(fail)?;
    let _ = s.set_nodelay(true);
    s.write_all(&create_packet(name, size.0, size.1))
        .map_err(fail)?;
    for u in rx {
        // Split to tev-sized pieces (a whole-film region can be large).
        for y0 in (0..u.rect[3]).step_by(MAX_UPDATE as usize) {
            for x0 in (0..u.rect[2]).step_by(MAX_UPDATE as usize) {
                let bw = (u.rect[2] - x0).min(MAX_UPDATE);
                let bh = (u.rect[3] - y0).min(MAX_UPDATE);
                let mut rgb = Vec::with_capacity((bw * bh * 3) as usize);
                for y in y0..y0 + bh {
                    let i = 3 * (y * u.rect[2] + x0) as usize;
                    rgb.extend_from_slice(&u.rgb[i..i + 3 * bw as usize]);
                }
                let rect = [u.rect[0] + x0, u.rect[1] + y0, bw, bh];
                for c in 0..CHANNELS.len() {
                    s.write_all(&update_packet(name, c, rect, &rgb))
                        .map_err(fail)?;
                }
            }
        }
    }
    s.flush().map_err(fail)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packets_carry_their_length_and_fields() {
        let p = create_packet("a", 3, 2);
        assert_eq!(
            u32::from_le_bytes(p[0..4].try_into().unwrap()) as usize,
            p.len()
        );
        assert_eq!(p[4], CREATE_IMAGE);
        assert_eq!(&p[6..8], b"a\0");
        assert_eq!(i32::from_le_bytes(p[8..12].try_into().unwrap()), 3);
        assert_eq!(&p[p.len() - 2..], b"B\0");
        let rgb = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0];
        let u = update_packet("a", 1, [1, 0, 2, 1], &rgb);
        assert_eq!(
            u32::from_le_bytes(u[0..4].try_into().unwrap()) as usize,
            u.len()
        );
        assert_eq!(u[4], UPDATE_IMAGE);
        assert_eq!(&u[6..10], b"a\0G\0");
        let tail = &u[u.len() - 8..];
        assert_eq!(f32::from_le_bytes(tail[0..4].try_into().unwrap()), 2.0);
        assert_eq!(f32::from_le_bytes(tail[4..8].try_into().unwrap()), 5.0);
        let c = close_packet("a");
        assert_eq!(c, [7, 0, 0, 0, CLOSE_IMAGE, b'a', 0]);
    }
}
