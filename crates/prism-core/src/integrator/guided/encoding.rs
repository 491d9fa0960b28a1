//! Bytes of what a guided render learns (the SD-tree, [`super::sd_tree`]), for its render state
//! ([`crate::render::state::IntegratorState`]): little-endian numbers, each list preceded by its
//! length. Decoding reads untrusted bytes: a length is checked against the bytes left before
//! anything is allocated, an index against what it points into, a number against its range, so
//! damaged bytes give a message naming what is wrong, never a panic.

/// Appends numbers to a byte vector.
#[derive(Debug, Default)]
pub struct Encoder {
    pub bytes: Vec<u8>,
}

impl Encoder {
    pub fn u8(&mut self, v: u8) {
        self.bytes.push(v);
    }

    pub fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }

    pub fn u32(&mut self, v: u32) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    pub fn i32(&mut self, v: i32) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u64(&mut self, v: u64) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    pub fn i128(&mut self, v: i128) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f64(&mut self, v: f64) {
        self.bytes.extend_from_slice(&v.to_le_bytes());
    }

    /// A list's length.
    pub fn length(&mut self, n: usize) {
        self.u64(n as u64);
    }
}

/// What is wrong with bytes being decoded, in words.
pub type Malformed = String;

/// Reads numbers from a byte slice, failing cleanly at its end.
#[derive(Debug)]
pub struct Decoder<'a> {
    bytes: &'a [u8],
    position: usize,
}

impl<'a> Decoder<'a> {
    pub fn new(bytes: &'a [u8]) -> Decoder<'a> {
        Decoder { bytes, position: 0 }
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], Malformed> {
        let end = self.position.saturating_add(N);
        let slice = self
            .bytes
            .get(self.position..end)
            .ok_or_else(|| "it ends too early".to_string())?;
        self.position = end;
        let mut out = [0; N];
        out.copy_from_slice(slice);
        Ok(out)
    }

    /// Bytes not read yet.
    pub fn left(&self) -> usize {
        self.bytes.len() - self.position
    }

    /// Fails unless every byte has been read.
    pub fn finish(&self) -> Result<(), Malformed> {
        if self.left() == 0 {
            Ok(())
        } else {
            Err(format!("{} bytes follow its end", self.left()))
        }
    }

    pub fn u8(&mut self) -> Result<u8, Malformed> {
        Ok(self.take::<1>()?[0])
    }

    pub fn bool(&mut self, what: &str) -> Result<bool, Malformed> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(format!("{what} is {v}, neither 0 nor 1")),
        }
    }

    pub fn u32(&mut self) -> Result<u32, Malformed> {
        self.take().map(u32::from_le_bytes)
    }

    pub fn i32(&mut self) -> Result<i32, Malformed> {
        self.take().map(i32::from_le_bytes)
    }

    pub fn u64(&mut self) -> Result<u64, Malformed> {
        self.take().map(u64::from_le_bytes)
    }

    pub fn i128(&mut self) -> Result<i128, Malformed> {
        self.take().map(i128::from_le_bytes)
    }

    /// A finite number of at least `min`, named `what` in the message.
    pub fn f32_at_least(&mut self, min: f32, what: &str) -> Result<f32, Malformed> {
        let v = self.take().map(f32::from_le_bytes)?;
        if v.is_finite() && v >= min {
            Ok(v)
        } else {
            Err(format!("{what} is {v}"))
        }
    }

    /// A finite number of at least `min`, named `what` in the message.
    pub fn f64_at_least(&mut self, min: f64, what: &str) -> Result<f64, Malformed> {
        let v = self.f64()?;
        if v.is_finite() && v >= min {
            Ok(v)
        } else {
            Err(format!("{what} is {v}"))
        }
    }

    /// Any number, infinities and NaN included.
    pub fn f64(&mut self) -> Result<f64, Malformed> {
        self.take().map(f64::from_le_bytes)
    }

    /// A list's length, where each item takes at least `item_bytes` bytes: more than the bytes
    /// left could hold is an error, so that a damaged length allocates nothing.
    pub fn length(&mut self, item_bytes: usize, what: &str) -> Result<usize, Malformed> {
        let n = self.u64()?;
        if n.saturating_mul(item_bytes.max(1) as u64) > self.left() as u64 {
            return Err(format!(
                "it declares {n} {what}, more than its {} bytes hold",
                self.left()
            ));
        }
        Ok(n as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_and_damage_is_named() {
        let mut e = Encoder::default();
        e.u8(7);
        e.bool(true);
        e.u32(0xdead_beef);
        e.i32(-5);
        e.u64(u64::MAX);
        e.i128(-(1 << 100));
        e.f32(1.5);
        e.f64(f64::INFINITY);
        e.length(2);
        e.u32(1);
        e.u32(2);
        let mut d = Decoder::new(&e.bytes);
        assert_eq!(d.u8(), Ok(7));
        assert_eq!(d.bool("b"), Ok(true));
        assert_eq!(d.u32(), Ok(0xdead_beef));
        assert_eq!(d.i32(), Ok(-5));
        assert_eq!(d.u64(), Ok(u64::MAX));
        assert_eq!(d.i128(), Ok(-(1 << 100)));
        assert_eq!(d.f32_at_least(0.0, "x"), Ok(1.5));
        assert_eq!(d.f64(), Ok(f64::INFINITY));
        assert_eq!(d.length(4, "items"), Ok(2));
        assert_eq!(d.u32(), Ok(1));
        assert_eq!(d.u32(), Ok(2));
        assert_eq!(d.finish(), Ok(()));
        assert!(d.u8().unwrap_err().contains("ends too early"));

        let mut e = Encoder::default();
        e.length(3);
        e.u32(1);
        let error = Decoder::new(&e.bytes).length(4, "items").unwrap_err();
        assert!(error.contains("3 items"), "{error}");
        let mut e = Encoder::default();
        e.f64(-1.0);
        e.u8(2);
        let mut d = Decoder::new(&e.bytes);
        assert!(
            d.f64_at_least(0.0, "weight")
                .unwrap_err()
                .contains("weight")
        );
        assert!(d.bool("flag").unwrap_err().contains("flag"));
    }
}
