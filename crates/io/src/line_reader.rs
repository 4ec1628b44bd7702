//! A `BufRead` over an in-memory file that counts the lines handed out, so that errors from a
//! line-by-line parser (tobj) can name the line they stopped at.

use std::io::{BufRead, Read};

pub struct LineCountingReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    newlines: usize,
}

impl<'a> LineCountingReader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        LineCountingReader {
            bytes,
            pos: 0,
            newlines: 0,
        }
    }

    /// 1-based number of the line the parser read last.
    pub fn current_line(&self) -> usize {
        let ends_mid_line = self.pos > 0 && self.bytes[self.pos - 1] != b'\n';
        (self.newlines + usize::from(ends_mid_line)).max(1)
    }
}

impl Read for LineCountingReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.bytes.len() - self.pos);
        buf[..n].copy_from_slice(&self.bytes[self.pos..self.pos + n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineCountingReader<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        // Hand out one line at a time so the count is exact when the parser stops.
        let rest = &self.bytes[self.pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| i + 1);
        Ok(&rest[..end])
    }

    fn consume(&mut self, amount: usize) {
        let end = (self.pos + amount).min(self.bytes.len());
        self.newlines += self.bytes[self.pos..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        self.pos = end;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_lines_as_they_are_read() {
        let mut r = LineCountingReader::new(b"a\nb\nc");
        let mut line = String::new();
        r.read_line(&mut line).unwrap();
        assert_eq!(r.current_line(), 1);
        r.read_line(&mut line).unwrap();
        assert_eq!(r.current_line(), 2);
        r.read_line(&mut line).unwrap();
        assert_eq!(r.current_line(), 3);
    }
}
