//! Watching a render: `--display-server` sends the developing image in tev's protocol (a
//! listener here decodes the packets as tev reads them and rebuilds the image, which must end
//! equal to the EXR), a missing viewer costs one warning, and `--write-partial-images` leaves a
//! valid EXR behind a render killed with kill -9.

use std::io::Read;
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use prism_core::image::read_exr;

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-preview-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Arguments rendering the bundled Cornell box at `width` × `height` with `spp` samples.
fn render_arguments(output: &Path, width: u32, height: u32, spp: u32) -> Vec<String> {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    vec![
        "render".into(),
        scene.to_str().unwrap().into(),
        "-D".into(),
        format!("resx={width}"),
        "-D".into(),
        format!("resy={height}"),
        "--spp".into(),
        spp.to_string(),
        "--threads".into(),
        "2".into(),
        "-o".into(),
        output.to_str().unwrap().into(),
    ]
}

fn prism(arguments: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(arguments)
        .output()
        .unwrap()
}

/// A packet as tev reads it (`IpcPacket`'s `IStream`): little-endian fields after a u32 length
/// that counts itself.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let value = self.bytes[self.at..self.at + N].try_into().unwrap();
        self.at += N;
        value
    }

    fn boolean(&mut self) -> bool {
        let [b] = self.take::<1>();
        assert!(b <= 1, "a boolean is 0 or 1");
        b == 1
    }

    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take())
    }

    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.take())
    }

    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }

    fn string(&mut self) -> String {
        let end = self.at + self.bytes[self.at..].iter().position(|&b| b == 0).unwrap();
        let text = String::from_utf8(self.bytes[self.at..end].to_vec()).unwrap();
        self.at = end + 1;
        text
    }

    fn strings(&mut self, count: i32) -> Vec<String> {
        (0..count).map(|_| self.string()).collect()
    }
}

/// The image a viewer rebuilds from the packets it received.
#[derive(Default)]
struct Viewer {
    name: String,
    width: usize,
    height: usize,
    channels: Vec<String>,
    /// Values per channel, row-major.
    values: Vec<Vec<f32>>,
    /// The image after each time its last tile (the bottom-right one) arrived.
    shown: Vec<Vec<Vec<f32>>>,
    updates: usize,
}

impl Viewer {
    fn receive(&mut self, packet: &[u8]) {
        let mut reader = Reader {
            bytes: packet,
            at: 0,
        };
        let length = u32::from_le_bytes(reader.take());
        assert_eq!(length as usize, packet.len());
        let [kind] = reader.take::<1>();
        match kind {
            4 => {
                assert!(self.name.is_empty(), "the image is created once");
                reader.boolean();
                self.name = reader.string();
                self.width = reader.i32() as usize;
                self.height = reader.i32() as usize;
                let count = reader.i32();
                self.channels = reader.strings(count);
                self.values = vec![vec![0.0; self.width * self.height]; self.channels.len()];
            }
            6 => {
                assert!(
                    !self.name.is_empty(),
                    "an update before the image was created"
                );
                reader.boolean();
                assert_eq!(reader.string(), self.name);
                let count = reader.i32();
                assert_eq!(reader.strings(count), self.channels);
                let [x, y, w, h] = [0; 4].map(|_| reader.i32() as usize);
                assert!(x + w <= self.width && y + h <= self.height);
                let offsets: Vec<i64> = (0..count).map(|_| reader.i64()).collect();
                let strides: Vec<i64> = (0..count).map(|_| reader.i64()).collect();
                let data: Vec<f32> = (0..(packet.len() - reader.at) / 4)
                    .map(|_| reader.f32())
                    .collect();
                for (c, values) in self.values.iter_mut().enumerate() {
                    for pixel in 0..w * h {
                        let index = (offsets[c] + pixel as i64 * strides[c]) as usize;
                        values[(y + pixel / w) * self.width + x + pixel % w] = data[index];
                    }
                }
                self.updates += 1;
                if x + w == self.width && y + h == self.height {
                    self.shown.push(self.values.clone());
                }
            }
            _ => panic!("unexpected packet type {kind}"),
        }
    }

    /// Reads packets from `stream` until it is closed.
    fn listen(mut stream: TcpStream) -> Viewer {
        let mut bytes = Vec::new();
        stream.read_to_end(&mut bytes).unwrap();
        let mut viewer = Viewer::default();
        let mut at = 0;
        while at < bytes.len() {
            let length = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            viewer.receive(&bytes[at..at + length]);
            at += length;
        }
        viewer
    }
}

/// The first connection to `listener`, waited for a minute at most.
fn accept(listener: &TcpListener) -> TcpStream {
    listener.set_nonblocking(true).unwrap();
    let start = Instant::now();
    loop {
        match listener.accept() {
            Ok((stream, _)) => {
                stream.set_nonblocking(false).unwrap();
                return stream;
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                assert!(
                    start.elapsed() < Duration::from_secs(60),
                    "prism did not connect in a minute"
                );
                std::thread::sleep(Duration::from_millis(5));
            }
            Err(e) => panic!("{e}"),
        }
    }
}

#[test]
fn the_display_server_rebuilds_the_image_pass_by_pass() {
    let dir = folder("display");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    let viewer = std::thread::spawn(move || Viewer::listen(accept(&listener)));
    let output = dir.join("image.exr");
    // 200 × 136 pixels: tiles of 128 × 128 leave partial ones on the right and at the bottom.
    let mut arguments = render_arguments(&output, 200, 136, 4);
    arguments.extend(["--display-server".into(), address]);
    let result = prism(&arguments);
    assert!(result.status.success(), "{result:?}");
    let viewer = viewer.join().unwrap();

    assert_eq!(viewer.name, output.display().to_string());
    assert_eq!((viewer.width, viewer.height), (200, 136));
    assert_eq!(viewer.channels, ["R", "G", "B"]);
    assert_eq!(viewer.updates % 4, 0, "every image is sent in four tiles");
    // Passes of 1, 1 and 2 samples (or smaller), then the end.
    assert!(viewer.shown.len() >= 4, "{} images", viewer.shown.len());
    let exr = read_exr(&output).unwrap();
    for (c, name) in viewer.channels.iter().enumerate() {
        let expected = exr.channel(name).unwrap();
        let last = &viewer.shown.last().unwrap()[c];
        assert!(
            last.iter()
                .zip(expected)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "channel {name} of the last image differs from the EXR's"
        );
        assert_ne!(
            &viewer.shown[0][c], last,
            "the first pass's image is the final one"
        );
    }
}

#[test]
fn without_a_display_server_the_render_goes_on_after_one_warning() {
    let dir = folder("no-display");
    // A port nothing listens on: one just released.
    let address = {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.local_addr().unwrap().to_string()
    };
    let output = dir.join("image.exr");
    let mut arguments = render_arguments(&output, 16, 16, 4);
    arguments.extend(["--display-server".into(), address]);
    let result = prism(&arguments);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{stderr}");
    assert_eq!(stderr.matches("no display server").count(), 1, "{stderr}");
    assert!(read_exr(&output).is_ok());
}

#[test]
fn partial_images_are_valid_exrs_after_kill_9() {
    let dir = folder("partial");
    let output = dir.join("image.exr");
    let mut arguments = render_arguments(&output, 32, 32, 100_000);
    arguments.extend([
        "--write-partial-images".into(),
        "--checkpoint-every".into(),
        "0.05".into(),
    ]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(&arguments)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !output.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(output.exists(), "no partial image was written in a minute");
    // Kill it later, likely while it replaces the image again.
    std::thread::sleep(Duration::from_millis(120));
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), None, "the render was not killed");
    let image = read_exr(&output).unwrap();
    assert_eq!((image.width, image.height), (32, 32));
    let luminance = image.channel("Y").unwrap();
    assert!(luminance.iter().all(|v| v.is_finite()));
    assert!(
        luminance.iter().any(|&v| v > 0.0),
        "the partial image is black"
    );
    assert!(output.with_extension("png").exists());
}
