//! `prism render --display-server HOST:PORT`: the developing image sent to a viewer that speaks
//! the network protocol of tev (github.com/Tom94/tev, `src/Ipc.cpp`), as pbrt-v4 does.
//!
//! The protocol is a TCP stream of packets. A packet is its length in bytes as a little-endian
//! u32 (the four length bytes included), a type byte, then the fields: a boolean as one byte,
//! integers and floats little-endian, a string as its bytes and a NUL. Prism sends
//! - CreateImage (type 4): grab focus, image name, width and height (i32), the number of
//!   channels (i32), the channel names;
//! - UpdateImage, version 3 (type 6): grab focus, image name, the number of channels (i32),
//!   the channel names, the tile's x, y, width and height (i32), each channel's offset, then
//!   each channel's stride (i64) into the values that follow, the values (f32).
//!
//! The image is created black when the render starts; after every pass and at the end it is
//! sent again in tiles of [`TILE`] × [`TILE`] pixels, its linear sRGB values interleaved
//! (channels `R`, `G`, `B`: offsets 0, 1, 2, stride 3). When the viewer cannot be reached, or
//! stops answering, one warning is printed and the render goes on without it.

use std::io::Write;
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::time::Duration;

use prism_core::film::Film;

/// The width and height of the tiles an image is sent in.
const TILE: u32 = 128;

/// The channels sent: the EXR's linear sRGB.
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// How long to wait for the viewer to accept the connection.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(2);

/// How long a packet may wait to be sent before the viewer is given up.
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);

/// The type bytes of the packets Prism sends.
const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE_V3: u8 = 6;

/// A packet of tev's protocol being written.
struct Packet(Vec<u8>);

impl Packet {
    /// A packet of type `kind`, its length to be filled in by [`Packet::finish`].
    fn new(kind: u8) -> Packet {
        let mut bytes = vec![0; 4];
        bytes.push(kind);
        Packet(bytes)
    }

    fn boolean(&mut self, value: bool) {
        self.0.push(u8::from(value));
    }

    fn i32(&mut self, value: i32) {
        self.0.extend_from_slice(&value.to_le_bytes());
    }

    fn i64(&mut self, value: i64) {
        self.0.extend_from_slice(&value.to_le_bytes());
    }

    fn string(&mut self, value: &str) {
        self.0.extend_from_slice(value.as_bytes());
        self.0.push(0);
    }

    fn finish(mut self) -> Vec<u8> {
        let length = u32::try_from(self.0.len()).expect("a tile's packet is far below 4 GiB");
        self.0[..4].copy_from_slice(&length.to_le_bytes());
        self.0
    }
}

/// The CreateImage packet of an image `name` of `width` × `height` pixels with [`CHANNELS`].
fn create_image(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut packet = Packet::new(CREATE_IMAGE);
    packet.boolean(true);
    packet.string(name);
    packet.i32(width as i32);
    packet.i32(height as i32);
    packet.i32(CHANNELS.len() as i32);
    for channel in CHANNELS {
        packet.string(channel);
    }
    packet.finish()
}

/// The UpdateImage packet of the tile at `x`, `y` of `width` × `height` pixels of the image
/// `name`, whose rows of `image_width` pixels `rgb` holds.
fn update_image(
    name: &str,
    rgb: &[[f32; 3]],
    image_width: u32,
    [x, y, width, height]: [u32; 4],
) -> Vec<u8> {
    let mut packet = Packet::new(UPDATE_IMAGE_V3);
    packet.boolean(false);
    packet.string(name);
    packet.i32(CHANNELS.len() as i32);
    for channel in CHANNELS {
        packet.string(channel);
    }
    for value in [x, y, width, height] {
        packet.i32(value as i32);
    }
    for offset in 0..CHANNELS.len() {
        packet.i64(offset as i64);
    }
    for _ in CHANNELS {
        packet.i64(CHANNELS.len() as i64);
    }
    packet.0.reserve(12 * (width * height) as usize);
    for row in y..y + height {
        let start = (row * image_width + x) as usize;
        for pixel in &rgb[start..start + width as usize] {
            for value in pixel {
                packet.0.extend_from_slice(&value.to_le_bytes());
            }
        }
    }
    packet.finish()
}

/// The tiles of a `width` × `height` image as x, y, width, height, row by row.
fn tiles(width: u32, height: u32) -> impl Iterator<Item = [u32; 4]> {
    (0..height).step_by(TILE as usize).flat_map(move |y| {
        (0..width)
            .step_by(TILE as usize)
            .map(move |x| [x, y, TILE.min(width - x), TILE.min(height - y)])
    })
}

/// A connection to a viewer showing one image; None once the viewer is lost.
pub struct DisplayServer {
    address: String,
    name: String,
    stream: Option<TcpStream>,
}

impl DisplayServer {
    /// Connects to the viewer at `address` (HOST:PORT) and creates the image `name` of
    /// `width` × `height` black pixels there. Without a viewer, warns and shows nothing.
    pub fn connect(address: &str, name: &str, width: u32, height: u32) -> DisplayServer {
        let mut server = DisplayServer {
            address: address.to_string(),
            name: name.to_string(),
            stream: None,
        };
        match open(address) {
            Ok(stream) => {
                server.stream = Some(stream);
                server.send(&create_image(name, width, height));
            }
            Err(error) => server.give_up(&error),
        }
        server
    }

    /// Sends the film's developing image, tile by tile.
    pub fn show(&mut self, film: &Film) {
        let rgb = film.linear_srgb();
        let size = film.crop.size;
        for tile in tiles(size.x, size.y) {
            if self.stream.is_none() {
                return;
            }
            self.send(&update_image(&self.name, &rgb, size.x, tile));
        }
    }

    fn send(&mut self, packet: &[u8]) {
        if let Some(stream) = &mut self.stream
            && let Err(error) = stream.write_all(packet)
        {
            self.give_up(&error);
        }
    }

    fn give_up(&mut self, error: &std::io::Error) {
        self.stream = None;
        eprintln!(
            "prism: warning: no display server at {} ({error}); rendering without a preview",
            self.address
        );
    }
}

/// A TCP stream to the first of `address`'s addresses that accepts, writes timing out.
fn open(address: &str) -> std::io::Result<TcpStream> {
    let addresses: Vec<SocketAddr> = address.to_socket_addrs()?.collect();
    let mut last_error = std::io::Error::other("the host has no address");
    for socket in addresses {
        match TcpStream::connect_timeout(&socket, CONNECT_TIMEOUT) {
            Ok(stream) => {
                stream.set_write_timeout(Some(WRITE_TIMEOUT))?;
                stream.set_nodelay(true)?;
                return Ok(stream);
            }
            Err(error) => last_error = error,
        }
    }
    Err(last_error)
}

/// Checks that `text` has the form HOST:PORT.
pub fn parse_address(text: &str) -> Result<String, String> {
    match text.rsplit_once(':') {
        Some((host, port)) if !host.is_empty() && port.parse::<u16>().is_ok() => {
            Ok(text.to_string())
        }
        _ => Err(format!(
            "expected HOST:PORT (tev listens on 127.0.0.1:14158), got \"{text}\""
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        let (width, height) = (300, 130);
        let mut covered = vec![0u8; (width * height) as usize];
        for [x, y, w, h] in tiles(width, height) {
            assert!(w <= TILE && h <= TILE && w > 0 && h > 0);
            for row in y..y + h {
                for column in x..x + w {
                    covered[(row * width + column) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }

    #[test]
    fn a_create_packet_is_laid_out_as_tev_reads_it() {
        let packet = create_image("a", 2, 3);
        let mut expected = Vec::new();
        expected.extend_from_slice(&26u32.to_le_bytes());
        expected.extend_from_slice(&[4, 1, b'a', 0]);
        for value in [2i32, 3, 3] {
            expected.extend_from_slice(&value.to_le_bytes());
        }
        expected.extend_from_slice(b"R\0G\0B\0");
        assert_eq!(packet, expected);
    }

    #[test]
    fn addresses_need_a_host_and_a_port() {
        assert!(parse_address("127.0.0.1:14158").is_ok());
        assert!(parse_address("localhost:1").is_ok());
        assert!(parse_address("[::1]:14158").is_ok());
        for bad in ["localhost", ":14158", "host:", "host:70000"] {
            assert!(parse_address(bad).is_err(), "{bad}");
        }
    }
}
