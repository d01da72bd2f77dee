//! A live preview in the tev image viewer (github.com/Tom94/tev), over its
//! network protocol, as pbrt-v4's `--display-server` does: the image is
//! created once, and each progressive pass sends the running average in
//! tiles.
//!
//! Each packet: its length (u32, little-endian, counting itself), a type
//! byte, then its fields: strings end with a NUL, integers are
//! little-endian. Create (type 4): grab-focus byte, name, width, height
//! (i32), channel count (i32), channel names. Update (type 6): grab-focus
//! byte, name, channel count, channel names, x, y, width, height (i32), per
//! channel an offset and a stride (i64, in floats), then the floats.

use crate::film::Film;
use std::io::{self, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE: u8 = 6;
/// Tiles of at most this many pixels a side (what tev's own clients send).
const TILE: u32 = 128;
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// A connection to tev showing one image.
pub struct Tev {
    stream: TcpStream,
    name: String,
    width: u32,
    height: u32,
}

fn packet(kind: u8, grab_focus: bool, name: &str, body: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut p = vec![0u8; 4];
    p.push(kind);
    p.push(grab_focus as u8);
    p.extend(name.bytes().filter(|&b| b != 0));
    p.push(0);
    body(&mut p);
    let len = p.len() as u32;
    p[..4].copy_from_slice(&len.to_le_bytes());
    p
}

fn names(p: &mut Vec<u8>) {
    p.extend((CHANNELS.len() as i32).to_le_bytes());
    for c in CHANNELS {
        p.extend(c.as_bytes());
        p.push(0);
    }
}

impl Tev {
    /// Connects to tev at `address` ("HOST:PORT"; tev listens on
    /// 127.0.0.1:14158 by default) and creates the image `name`.
    pub fn connect(address: &str, name: &str, width: u32, height: u32) -> io::Result<Tev> {
        let mut last = io::Error::new(io::ErrorKind::NotFound, format!("{address}: no such address"));
        for addr in address.to_socket_addrs()? {
            match TcpStream::connect_timeout(&addr, Duration::from_secs(3)) {
                Ok(stream) => {
                    stream.set_write_timeout(Some(Duration::from_secs(10)))?;
                    let mut tev = Tev { stream, name: name.to_string(), width, height };
                    let create = packet(CREATE_IMAGE, true, name, |p| {
                        p.extend((width as i32).to_le_bytes());
                        p.extend((height as i32).to_le_bytes());
                        names(p);
                    });
                    tev.stream.write_all(&create)?;
                    return Ok(tev);
                }
                Err(e) => last = e,
            }
        }
        Err(last)
    }

    /// Sends `film` (the image's size) as the image's new pixels.
    pub fn update(&mut self, film: &Film) -> io::Result<()> {
        assert_eq!((film.width, film.height), (self.width, self.height));
        for y0 in (0..self.height).step_by(TILE as usize) {
            for x0 in (0..self.width).step_by(TILE as usize) {
                let (w, h) = (TILE.min(self.width - x0), TILE.min(self.height - y0));
                let update = packet(UPDATE_IMAGE, false, &self.name, |p| {
                    names(p);
                    for v in [x0, y0, w, h] {
                        p.extend((v as i32).to_le_bytes());
                    }
                    // Interleaved RGB: channel c at offset c, stride 3.
                    for c in 0..3i64 {
                        p.extend(c.to_le_bytes());
                    }
                    for _ in 0..3 {
                        p.extend(3i64.to_le_bytes());
                    }
                    for y in y0..y0 + h {
                        for x in x0..x0 + w {
                            for v in film.get(x, y).to_array() {
                                p.extend(v.to_le_bytes());
                            }
                        }
                    }
                });
                self.stream.write_all(&update)?;
            }
        }
        self.stream.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Color;
    use std::io::Read;
    use std::net::TcpListener;

    /// A listener that decodes tev's packets: the image is created with its
    /// size and channels, and the updates' tiles put together give the
    /// film's pixels exactly.
    #[test]
    fn a_listener_decodes_the_image() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let address = listener.local_addr().unwrap().to_string();
        let (w, h) = (150u32, 130u32);
        let film = Film {
            width: w,
            height: h,
            pixels: (0..w * h).map(|i| Color::new(i as f32, 0.5, -(i as f32) * 1e-3)).collect(),
        };
        let server = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            let mut bytes = Vec::new();
            s.read_to_end(&mut bytes).unwrap();
            bytes
        });
        let mut tev = Tev::connect(&address, "photonmap", w, h).unwrap();
        tev.update(&film).unwrap();
        drop(tev);
        let bytes = server.join().unwrap();

        struct Reader<'a>(&'a [u8], usize);
        impl Reader<'_> {
            fn take(&mut self, n: usize) -> &[u8] {
                self.1 += n;
                &self.0[self.1 - n..self.1]
            }
            fn i32(&mut self) -> i32 {
                i32::from_le_bytes(self.take(4).try_into().unwrap())
            }
            fn i64(&mut self) -> i64 {
                i64::from_le_bytes(self.take(8).try_into().unwrap())
            }
            fn string(&mut self) -> String {
                let end = self.0[self.1..].iter().position(|&b| b == 0).unwrap();
                let s = String::from_utf8(self.take(end).to_vec()).unwrap();
                self.take(1);
                s
            }
        }
        let mut r = Reader(&bytes, 0);
        let mut seen = vec![None; (w * h) as usize];
        let mut created = false;
        while r.1 < bytes.len() {
            let start = r.1;
            let len = u32::from_le_bytes(r.take(4).try_into().unwrap()) as usize;
            let kind = r.take(2)[0];
            assert_eq!(r.string(), "photonmap");
            if kind == CREATE_IMAGE {
                assert_eq!((r.i32(), r.i32(), r.i32()), (w as i32, h as i32, 3));
                let chans: Vec<String> = (0..3).map(|_| r.string()).collect();
                assert_eq!(chans, ["R", "G", "B"]);
                created = true;
            } else {
                assert_eq!(kind, UPDATE_IMAGE);
                assert!(created, "an update before the image was created");
                assert_eq!(r.i32(), 3);
                let chans: Vec<String> = (0..3).map(|_| r.string()).collect();
                assert_eq!(chans, ["R", "G", "B"]);
                let (x0, y0, tw, th) = (r.i32(), r.i32(), r.i32(), r.i32());
                let offsets: Vec<i64> = (0..3).map(|_| r.i64()).collect();
                let strides: Vec<i64> = (0..3).map(|_| r.i64()).collect();
                let floats: Vec<f32> =
                    (0..tw * th * 3).map(|_| f32::from_le_bytes(r.take(4).try_into().unwrap())).collect();
                for y in 0..th {
                    for x in 0..tw {
                        let p = (y * tw + x) as i64;
                        let v = |c: usize| floats[(offsets[c] + p * strides[c]) as usize];
                        seen[((y0 + y) as u32 * w + (x0 + x) as u32) as usize] = Some(Color::new(v(0), v(1), v(2)));
                    }
                }
            }
            assert_eq!(r.1 - start, len, "a packet's length counts its bytes");
        }
        let seen: Vec<Color> = seen.into_iter().map(|p| p.expect("every pixel sent")).collect();
        assert_eq!(seen, film.pixels);
    }
}
