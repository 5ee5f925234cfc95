//! Logging macros: `defmt` on the target (feature `defmt`), the `log` crate
//! on the host (feature `log`; the simulator prints it with virtual-time
//! stamps), nothing otherwise. Arguments use plain `{}` (types implementing
//! `defmt::Format` and `Display`) or `{:?}` (`defmt::Format` and `Debug`).

macro_rules! make_log_macro {
    ($d:tt $name:ident => $backend:ident) => {
        #[allow(unused_macros)]
        macro_rules! $name {
                                            ($d($d arg:tt)*) => {{
                                                #[cfg(feature = "defmt")]
                                                ::defmt::$backend!($d($d arg)*);
                                                #[cfg(feature = "log")]
                                                ::log::$backend!($d($d arg)*);
                                                #[cfg(not(any(feature = "defmt", feature = "log")))]
                                                if false {
                                                    let _ = ::core::format_args!($d($d arg)*);
                                                }
                                            }};
                                        }
        #[allow(unused_imports)]
        pub(crate) use $name;
    };
}

make_log_macro!($ trace => trace);
make_log_macro!($ debug => debug);
make_log_macro!($ info => info);
make_log_macro!($ warning => warn);
make_log_macro!($ error => error);
