//! Where requested outputs go: a slice of `(t, x)` or a callback.

/// Where requested outputs go.
pub(crate) trait Sink<T, const S: usize> {
    fn len(&self) -> usize;
    fn time(&self, i: usize) -> f64;
    fn put(&mut self, i: usize, x: &[T; S]);
}

pub(crate) struct SliceSink<'a, T, const S: usize>(pub(crate) &'a mut [(f64, [T; S])]);

impl<T: Copy, const S: usize> Sink<T, S> for SliceSink<'_, T, S> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.0[i].0
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        self.0[i].1 = *x;
    }
}

pub(crate) struct CallbackSink<'a, 'b, T, const S: usize> {
    pub(crate) times: &'a [f64],
    pub(crate) cb: &'b mut dyn FnMut(f64, &[T; S]),
}

impl<T, const S: usize> Sink<T, S> for CallbackSink<'_, '_, T, S> {
    fn len(&self) -> usize {
        self.times.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.times[i]
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        (self.cb)(self.times[i], x)
    }
}
