//! Scope guards for construction: a part made before a later `?` is released on that error
//! path. GPU objects are otherwise destroyed explicitly (`destroy(&mut self, ctx)`); only
//! these guards and the device owner act on drop.
use super::{Buffer, Context};

/// Anything with an explicit `destroy`.
pub trait Destroy {
    fn destroy(&mut self, ctx: &Context);
}

impl Destroy for Buffer {
    fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_buffer(self);
    }
}

impl Destroy for super::Image {
    fn destroy(&mut self, ctx: &Context) {
        ctx.destroy_image(self);
    }
}

impl<T: Destroy> Destroy for Option<T> {
    fn destroy(&mut self, ctx: &Context) {
        if let Some(v) = self {
            v.destroy(ctx);
        }
    }
}

impl<T: Destroy> Destroy for Vec<T> {
    fn destroy(&mut self, ctx: &Context) {
        for v in self {
            v.destroy(ctx);
        }
    }
}

impl<T: Destroy, const N: usize> Destroy for [T; N] {
    fn destroy(&mut self, ctx: &Context) {
        for v in self {
            v.destroy(ctx);
        }
    }
}

/// Implement `Destroy` for types with an inherent `destroy(&mut self, &Context)`.
#[macro_export]
macro_rules! impl_destroy {
    ($($t:ty),* $(,)?) => {$(
        impl $crate::Destroy for $t {
            fn destroy(&mut self, ctx: &$crate::Context) {
                <$t>::destroy(self, ctx)
            }
        }
    )*};
}

/// Holds a value and destroys it when dropped, unless `take`n.
pub struct Guard<'c, T: Destroy> {
    ctx: &'c Context,
    value: Option<T>,
}

impl<'c, T: Destroy> Guard<'c, T> {
    pub fn new(ctx: &'c Context, value: T) -> Self {
        Self {
            ctx,
            value: Some(value),
        }
    }

    /// The value, no longer guarded.
    pub fn take(mut self) -> T {
        self.value
            .take()
            .expect("guard holds its value until taken")
    }
}

impl<T: Destroy> std::ops::Deref for Guard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value
            .as_ref()
            .expect("guard holds its value until taken")
    }
}

impl<T: Destroy> std::ops::DerefMut for Guard<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value
            .as_mut()
            .expect("guard holds its value until taken")
    }
}

impl<T: Destroy> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        if let Some(mut v) = self.value.take() {
            v.destroy(self.ctx);
        }
    }
}
