//! Standard base64 (RFC 4648 §4, with `=` padding): every 3 bytes become 4 characters of
//! `A–Z a–z 0–9 + /`. Used to put binary data (meshes, link orientations) inside the viewer page;
//! the coding is the `base64` crate's standard engine.

use ::base64::engine::general_purpose::STANDARD;
use ::base64::Engine as _;

/// `bytes` in base64.
pub fn encode(bytes: &[u8]) -> String {
    STANDARD.encode(bytes)
}

/// The bytes of base64 text `s`; `None` for a character outside the alphabet, a length that
/// is not a multiple of 4, or padding out of place.
pub fn decode(s: &str) -> Option<Vec<u8>> {
    STANDARD.decode(s).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc_4648_test_vectors() {
        // RFC 4648 §10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(encode(plain.as_bytes()), coded);
            assert_eq!(decode(coded).unwrap(), plain.as_bytes());
        }
        let all: Vec<u8> = (0..=255).collect();
        assert_eq!(decode(&encode(&all)).unwrap(), all);
        assert_eq!(decode("Zm9"), None);
        assert_eq!(decode("Zm9*"), None);
        // Padding inside the text, and bits left over in the last character (the old coder
        // took both), are refused.
        assert_eq!(decode("Zg==Zg=="), None);
        assert_eq!(decode("Zh=="), None);
    }
}
