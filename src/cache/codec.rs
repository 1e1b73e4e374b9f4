//! The byte layout of a cache entry's payload: little-endian integers, `f64` as their bit
//! patterns (so a table read back is the table written, to the bit), lengths before sequences.
//! A [`Reader`] refuses to read past the end; the decoders built on it check every index they
//! read, so that a payload that passed its checksum but is inconsistent fails as an error, never
//! as a panic.

use crate::{Error, Result};

/// The error of a payload that does not decode.
pub(crate) fn malformed(reason: impl Into<String>) -> Error {
    Error::invalid("table cache entry", reason)
}

/// Appends values to a byte buffer.
#[derive(Debug, Default)]
pub(crate) struct Writer {
    buf: Vec<u8>,
}

impl Writer {
    /// An empty buffer.
    pub(crate) fn new() -> Self {
        Writer::default()
    }

    /// The bytes written.
    pub(crate) fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    /// One byte.
    pub(crate) fn u8(&mut self, x: u8) {
        self.buf.push(x);
    }

    /// A flag as one byte (0 or 1).
    pub(crate) fn bool(&mut self, x: bool) {
        self.u8(u8::from(x));
    }

    /// A count or an index (as 8 bytes).
    pub(crate) fn usize(&mut self, x: usize) {
        self.buf.extend_from_slice(&(x as u64).to_le_bytes());
    }

    /// A number as its bit pattern.
    pub(crate) fn f64(&mut self, x: f64) {
        self.buf.extend_from_slice(&x.to_bits().to_le_bytes());
    }

    /// A length, then the numbers.
    pub(crate) fn f64s(&mut self, xs: &[f64]) {
        self.usize(xs.len());
        for &x in xs {
            self.f64(x);
        }
    }
}

/// Reads values back in the order a [`Writer`] wrote them.
#[derive(Debug)]
pub(crate) struct Reader<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// Reads `buf` from its start.
    pub(crate) fn new(buf: &'a [u8]) -> Self {
        Reader { buf, at: 0 }
    }

    /// Whether every byte has been read.
    pub(crate) fn is_done(&self) -> bool {
        self.at == self.buf.len()
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.buf.len());
        let Some(end) = end else {
            return Err(malformed(format!(
                "payload ends early, at byte {} of {}",
                self.at,
                self.buf.len()
            )));
        };
        let mut out = [0u8; N];
        out.copy_from_slice(&self.buf[self.at..end]);
        self.at = end;
        Ok(out)
    }

    /// One byte.
    pub(crate) fn u8(&mut self) -> Result<u8> {
        Ok(self.take::<1>()?[0])
    }

    /// A flag written by [`Writer::bool`].
    pub(crate) fn bool(&mut self) -> Result<bool> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(malformed(format!("a flag of value {b}"))),
        }
    }

    /// A count or an index.
    pub(crate) fn usize(&mut self) -> Result<usize> {
        let x = u64::from_le_bytes(self.take::<8>()?);
        usize::try_from(x).map_err(|_| malformed(format!("a count of {x}")))
    }

    /// A count of items of at least `item_bytes` bytes each, no more than the bytes left allow
    /// (a corrupt count cannot ask for a huge allocation).
    pub(crate) fn count(&mut self, item_bytes: usize) -> Result<usize> {
        let n = self.usize()?;
        let left = self.buf.len() - self.at;
        if n.checked_mul(item_bytes.max(1)).is_none_or(|b| b > left) {
            return Err(malformed(format!(
                "a count of {n} items with {left} bytes left"
            )));
        }
        Ok(n)
    }

    /// An index below `len`.
    pub(crate) fn index(&mut self, len: usize) -> Result<usize> {
        let i = self.usize()?;
        if i < len {
            Ok(i)
        } else {
            Err(malformed(format!("index {i} of {len} items")))
        }
    }

    /// A number from its bit pattern.
    pub(crate) fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_bits(u64::from_le_bytes(self.take::<8>()?)))
    }

    /// A finite number.
    pub(crate) fn finite(&mut self) -> Result<f64> {
        let x = self.f64()?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(malformed(format!("a non-finite number {x}")))
        }
    }

    /// Numbers written by [`Writer::f64s`], each finite.
    pub(crate) fn finite_f64s(&mut self) -> Result<Vec<f64>> {
        let n = self.count(8)?;
        (0..n).map(|_| self.finite()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_back_as_written_and_a_short_buffer_is_an_error() {
        let mut w = Writer::new();
        w.u8(7);
        w.bool(true);
        w.usize(123_456_789);
        w.f64(-0.0);
        w.f64s(&[1.5, f64::MIN_POSITIVE / 4.0]);
        let bytes = w.into_bytes();
        let mut r = Reader::new(&bytes);
        assert_eq!(r.u8().unwrap(), 7);
        assert!(r.bool().unwrap());
        assert_eq!(r.usize().unwrap(), 123_456_789);
        assert_eq!(r.f64().unwrap().to_bits(), (-0.0f64).to_bits());
        let xs = r.finite_f64s().unwrap();
        assert_eq!(xs[1].to_bits(), (f64::MIN_POSITIVE / 4.0).to_bits());
        assert!(r.is_done());
        assert!(r.u8().is_err());
        // A count larger than the bytes left is refused before anything is allocated.
        let mut w = Writer::new();
        w.usize(usize::MAX / 2);
        let bytes = w.into_bytes();
        assert!(Reader::new(&bytes).finite_f64s().is_err());
        let mut nan = Writer::new();
        nan.f64(f64::NAN);
        assert!(Reader::new(&nan.into_bytes()).finite().is_err());
    }
}
