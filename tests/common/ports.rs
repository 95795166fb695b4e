//! A free loopback port for a server a test starts in another process.

use std::net::TcpListener;
use std::sync::atomic::{AtomicU16, Ordering};

/// Below Linux's ephemeral range (32768–60999 by default): no port the OS hands out for `:0`
/// (the other tests' servers, started beside this one) can take the port between this check
/// and the child's own bind. Each call in a process tries the next one.
const FIRST: u16 = 20_000;
const PORTS: u16 = 12_000;

/// A loopback port that was free just now, from a range the OS does not hand out for `:0`,
/// different for each call in this process and, by its process id, likely for another test
/// process too.
pub fn free_port() -> u16 {
    static NEXT: AtomicU16 = AtomicU16::new(0);
    let base = (std::process::id() % u32::from(PORTS)) as u16;
    for _ in 0..PORTS {
        let offset = (base + NEXT.fetch_add(1, Ordering::Relaxed) % PORTS) % PORTS;
        let port = FIRST + offset;
        if TcpListener::bind(("127.0.0.1", port)).is_ok() {
            return port;
        }
    }
    panic!("no free loopback port in {FIRST}..{}", FIRST + PORTS)
}
