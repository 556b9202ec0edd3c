//! Standard output that ends quietly on a closed pipe.
//!
//! `dualsplit simulate ... | head -1` closes the pipe after one line; `println!` would then
//! panic ("failed printing to stdout: Broken pipe"). `outln!` and `out!` write through
//! [`write_out`] instead: once the reader has gone, further output is dropped, the command
//! carries on (so the files it writes, a PNG or a JSON, are still written) and exits with
//! its own status, printing nothing about the pipe, as tools killed by SIGPIPE do. Any other
//! write error is remembered and ends the command with an error ([`take_error`]).

use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output's reader has gone.
static CLOSED: AtomicBool = AtomicBool::new(false);
/// The first write error other than a closed pipe.
static ERROR: Mutex<Option<std::io::Error>> = Mutex::new(None);

/// Writes `args` to standard output (see the module).
pub fn write_out(args: std::fmt::Arguments<'_>) {
    if CLOSED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            CLOSED.store(true, Ordering::Relaxed);
        } else {
            CLOSED.store(true, Ordering::Relaxed);
            let mut first = ERROR.lock().unwrap_or_else(|p| p.into_inner());
            first.get_or_insert(e);
        }
    }
}

/// The first error writing standard output other than a closed pipe, if any.
pub fn take_error() -> Option<std::io::Error> {
    ERROR.lock().unwrap_or_else(|p| p.into_inner()).take()
}

/// `println!` that ends quietly on a closed pipe ([`write_out`]).
macro_rules! outln {
    () => {
        $crate::out::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` that ends quietly on a closed pipe ([`write_out`]).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::out::write_out(format_args!($($arg)*))
    };
}
