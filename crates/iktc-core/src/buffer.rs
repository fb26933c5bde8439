//! A preallocated vector whose clone keeps its capacity.
//!
//! The real-time path pushes into vectors sized once at construction and never beyond that
//! size, so that a tick allocates nothing. A derived `Clone` of a `Vec` keeps only its length:
//! a cloned controller would then allocate on its first pushes (and a capacity check would
//! see a full vector). [`Buffer`] clones with the original capacity.

use std::ops::{Deref, DerefMut};

/// A `Vec` whose [`Clone`] reserves the capacity of the original.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct Buffer<T>(Vec<T>);

impl<T> Buffer<T> {
    /// An empty buffer with room for `capacity` elements.
    pub(crate) fn with_capacity(capacity: usize) -> Self {
        Self(Vec::with_capacity(capacity))
    }
}

impl<T: Clone> Clone for Buffer<T> {
    fn clone(&self) -> Self {
        let mut v = Vec::with_capacity(self.0.capacity());
        v.extend_from_slice(&self.0);
        Self(v)
    }
}

impl<T> Deref for Buffer<T> {
    type Target = Vec<T>;
    fn deref(&self) -> &Vec<T> {
        &self.0
    }
}

impl<T> DerefMut for Buffer<T> {
    fn deref_mut(&mut self) -> &mut Vec<T> {
        &mut self.0
    }
}

#[cfg(test)]
mod tests {
    use super::Buffer;

    #[test]
    fn a_clone_keeps_the_capacity_and_the_content() {
        let mut b: Buffer<usize> = Buffer::with_capacity(17);
        b.extend([3, 1, 4]);
        let c = b.clone();
        assert_eq!(c.capacity(), b.capacity());
        assert!(c.capacity() >= 17);
        assert_eq!(&c[..], &[3, 1, 4]);
    }
}
