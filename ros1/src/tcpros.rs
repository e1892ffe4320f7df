//! TCPROS connection headers and message framing.

use std::collections::BTreeMap;
use std::io::{Read, Write};

use crate::error::{Error, Result};

/// Largest header or message accepted from a peer (bytes): a 4K RGB image is ~25 MB.
pub const MAX_FRAME_BYTES: usize = 64 << 20;

/// Writes a connection header: a u32 length, then `key=value` fields each with a u32 length.
pub fn write_header<W: Write>(out: &mut W, fields: &[(&str, &str)]) -> std::io::Result<()> {
    let mut body = Vec::new();
    for (k, v) in fields {
        let len = k.len() + 1 + v.len();
        body.extend_from_slice(&u32::try_from(len).unwrap_or(u32::MAX).to_le_bytes());
        body.extend_from_slice(k.as_bytes());
        body.push(b'=');
        body.extend_from_slice(v.as_bytes());
    }
    out.write_all(&u32::try_from(body.len()).unwrap_or(u32::MAX).to_le_bytes())?;
    out.write_all(&body)?;
    out.flush()
}

/// Reads one length-prefixed frame into `buf` (reused).
pub fn read_frame<R: Read>(input: &mut R, buf: &mut Vec<u8>) -> Result<()> {
    let mut len = [0u8; 4];
    input.read_exact(&mut len)?;
    let len = u32::from_le_bytes(len) as usize;
    if len > MAX_FRAME_BYTES {
        return Err(Error::protocol(format!("TCPROS frame of {len} bytes")));
    }
    buf.clear();
    buf.resize(len, 0);
    input.read_exact(buf)?;
    Ok(())
}

/// Reads a connection header into its fields.
pub fn read_header<R: Read>(input: &mut R) -> Result<BTreeMap<String, String>> {
    let mut buf = Vec::new();
    read_frame(input, &mut buf)?;
    parse_header(&buf)
}

/// Parses a connection header's body.
pub fn parse_header(mut bytes: &[u8]) -> Result<BTreeMap<String, String>> {
    let mut fields = BTreeMap::new();
    while !bytes.is_empty() {
        if bytes.len() < 4 {
            return Err(Error::protocol("truncated TCPROS header field"));
        }
        let len = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as usize;
        bytes = &bytes[4..];
        if bytes.len() < len {
            return Err(Error::protocol(
                "TCPROS header field longer than the header",
            ));
        }
        let field = String::from_utf8_lossy(&bytes[..len]);
        bytes = &bytes[len..];
        let (k, v) = field
            .split_once('=')
            .ok_or_else(|| Error::protocol(format!("TCPROS header field without '=': {field}")))?;
        fields.insert(k.to_owned(), v.to_owned());
    }
    Ok(fields)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_round_trip() -> Result<()> {
        let mut out = Vec::new();
        write_header(
            &mut out,
            &[("callerid", "/rover"), ("topic", "/odom"), ("md5sum", "*")],
        )?;
        let back = read_header(&mut out.as_slice())?;
        assert_eq!(back.get("topic").map(String::as_str), Some("/odom"));
        assert_eq!(back.get("md5sum").map(String::as_str), Some("*"));
        assert_eq!(back.len(), 3);
        Ok(())
    }

    #[test]
    fn bad_headers_are_errors_not_panics() {
        assert!(parse_header(&[1, 0, 0]).is_err());
        assert!(parse_header(&[9, 0, 0, 0, b'a']).is_err());
        assert!(parse_header(&[1, 0, 0, 0, b'a']).is_err());
        let huge = (MAX_FRAME_BYTES as u32 + 1).to_le_bytes();
        assert!(read_frame(&mut huge.as_slice(), &mut Vec::new()).is_err());
    }
}
