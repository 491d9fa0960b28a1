//! How a plugin class is declared: its interface, a trait whose required methods every plugin of
//! the class must answer and whose provided methods have a default body a plugin may override,
//! and the enum of its plugins, one variant per plugin type, which implements the same trait by
//! an exhaustive `match` (no wildcard arm, no dynamic dispatch in the hot path). Adding a plugin
//! is then adding a variant: the compiler asks for each required method, and the enum answers
//! every method, required or provided, with the plugin's own.
//!
//! [`plugin_class!`] writes the trait, the enum, a `From` conversion per plugin type and the
//! enum's forwarding implementation from one declaration:
//!
//! ```ignore
//! plugin_class! {
//!     /// The interface.
//!     pub trait Kernel {
//!         /// A required method, answered by every plugin.
//!         fn radius(&self) -> f32;
//!         /// A provided method: a default in terms of the required ones, which a plugin may
//!         /// override.
//!         fn diameter(&self) -> f32 {
//!             2.0 * self.radius()
//!         }
//!     }
//!     /// The plugins.
//!     #[derive(Clone, Debug)]
//!     pub enum Filter {
//!         Box(BoxFilter),
//!         Tent(TentFilter),
//!     }
//! }
//! ```
//!
//! Methods take `&self` or `&mut self` and arguments written `name: Type`. The enum forwards
//! each of them, provided ones included, to the plugin of the variant: a plugin's override is
//! what the enum answers, and a plugin that keeps the default answers with the default.

macro_rules! plugin_class {
    (
        $(#[$trait_meta:meta])*
        $vis:vis trait $trait:ident {
            $($methods:tt)*
        }
        $(#[$enum_meta:meta])*
        $enum_vis:vis enum $enum:ident {
            $($(#[$variant_meta:meta])* $variant:ident($plugin:ty),)+
        }
    ) => {
        $(#[$trait_meta])*
        $vis trait $trait {
            $crate::dispatch::plugin_class!(@declare $($methods)*);
        }

        $(#[$enum_meta])*
        $enum_vis enum $enum {
            $($(#[$variant_meta])* $variant($plugin),)+
        }

        $(impl From<$plugin> for $enum {
            #[inline]
            fn from(plugin: $plugin) -> $enum {
                $enum::$variant(plugin)
            }
        })+

        impl $trait for $enum {
            $crate::dispatch::plugin_class!(@forward $enum [$($variant)+] $($methods)*);
        }
    };

    (@declare) => {};
    (@declare
        $(#[$m:meta])* fn $name:ident(&self $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)?;
        $($rest:tt)*
    ) => {
        $(#[$m])* fn $name(&self $(, $arg: $ty)*) $(-> $ret)?;
        $crate::dispatch::plugin_class!(@declare $($rest)*);
    };
    (@declare
        $(#[$m:meta])* fn $name:ident(&mut self $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)?;
        $($rest:tt)*
    ) => {
        $(#[$m])* fn $name(&mut self $(, $arg: $ty)*) $(-> $ret)?;
        $crate::dispatch::plugin_class!(@declare $($rest)*);
    };
    (@declare
        $(#[$m:meta])* fn $name:ident($($params:tt)*) $(-> $ret:ty)? $body:block
        $($rest:tt)*
    ) => {
        $(#[$m])* fn $name($($params)*) $(-> $ret)? $body
        $crate::dispatch::plugin_class!(@declare $($rest)*);
    };

    (@forward $enum:ident [$($variant:ident)+]) => {};
    (@forward $enum:ident [$($variant:ident)+]
        $(#[$m:meta])* fn $name:ident(&self $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)?;
        $($rest:tt)*
    ) => {
        #[inline]
        fn $name(&self $(, $arg: $ty)*) $(-> $ret)? {
            $crate::dispatch::plugin_class!(@match self, $enum, [$($variant)+], $name, ($($arg),*))
        }
        $crate::dispatch::plugin_class!(@forward $enum [$($variant)+] $($rest)*);
    };
    (@forward $enum:ident [$($variant:ident)+]
        $(#[$m:meta])* fn $name:ident(&mut self $(, $arg:ident: $ty:ty)* $(,)?) $(-> $ret:ty)?;
        $($rest:tt)*
    ) => {
        #[inline]
        fn $name(&mut self $(, $arg: $ty)*) $(-> $ret)? {
            $crate::dispatch::plugin_class!(@match self, $enum, [$($variant)+], $name, ($($arg),*))
        }
        $crate::dispatch::plugin_class!(@forward $enum [$($variant)+] $($rest)*);
    };
    (@forward $enum:ident [$($variant:ident)+]
        $(#[$m:meta])* fn $name:ident($($params:tt)*) $(-> $ret:ty)? $body:block
        $($rest:tt)*
    ) => {
        $crate::dispatch::plugin_class!(
            @forward $enum [$($variant)+] fn $name($($params)*) $(-> $ret)?; $($rest)*
        );
    };

    (@match $receiver:ident, $enum:ident, [$($variant:ident)+], $name:ident, $args:tt) => {
        match $receiver {
            $($enum::$variant(plugin) => plugin.$name $args,)+
        }
    };
}

pub(crate) use plugin_class;

#[cfg(test)]
mod tests {
    plugin_class! {
        /// Numbers that know their double.
        pub trait Doubled {
            fn value(&self) -> f32;
            fn scale(&mut self, factor: f32);
            fn double(&self) -> f32 {
                2.0 * self.value()
            }
        }
        #[derive(Debug, PartialEq)]
        pub enum Number {
            Whole(Whole),
            Half(Half),
            Capped(Capped),
        }
    }

    #[derive(Debug, PartialEq)]
    pub struct Whole(f32);
    #[derive(Debug, PartialEq)]
    pub struct Half(f32);
    /// A number whose double stops at 10.
    #[derive(Debug, PartialEq)]
    pub struct Capped(f32);

    impl Doubled for Whole {
        fn value(&self) -> f32 {
            self.0
        }
        fn scale(&mut self, factor: f32) {
            self.0 *= factor;
        }
    }

    impl Doubled for Half {
        fn value(&self) -> f32 {
            0.5 * self.0
        }
        fn scale(&mut self, factor: f32) {
            self.0 *= factor;
        }
    }

    impl Doubled for Capped {
        fn value(&self) -> f32 {
            self.0
        }
        fn scale(&mut self, factor: f32) {
            self.0 *= factor;
        }
        fn double(&self) -> f32 {
            (2.0 * self.0).min(10.0)
        }
    }

    /// The enum answers a provided method with the default where a plugin keeps it and with
    /// the plugin's override where it has one.
    #[test]
    fn the_enum_forwards_every_method_to_the_plugin() {
        let mut numbers = [
            Number::from(Whole(3.0)),
            Number::from(Half(3.0)),
            Number::from(Capped(8.0)),
        ];
        assert_eq!(numbers[0].double(), 6.0);
        assert_eq!(numbers[1].double(), 3.0);
        assert_eq!(numbers[2].double(), 10.0);
        numbers[1].scale(2.0);
        assert_eq!(numbers[1], Number::Half(Half(6.0)));
    }
}
