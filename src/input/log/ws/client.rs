//! The connection: a blocking WebSocket over one TCP stream (`tungstenite`, plain `ws://`), a
//! connect timeout, a bounded frame size, both Foxglove subprotocols offered, and every
//! failure said in words that name the URL.

use std::io::ErrorKind;
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use tungstenite::client::IntoClientRequest;
use tungstenite::handshake::HandshakeError;
use tungstenite::http::HeaderValue;
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use super::protocol::SUBPROTOCOLS;

/// How long connecting (TCP and the WebSocket handshake) may take.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
/// The largest frame (and message) accepted: 16 MiB, far above a pose message (< 1 KiB) and
/// a `/tf` burst; a larger one ends the connection with this bound named.
pub const MAX_FRAME: usize = 16 << 20;
/// How long one read waits before the caller looks at its clock and Ctrl-C again.
pub const POLL: Duration = Duration::from_millis(50);

/// A `ws://HOST:PORT[/PATH]` URL split into what the connection needs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WsUrl {
    /// The URL as given.
    pub url: String,
    /// The host and port, `HOST:PORT` (port 8765, foxglove_bridge's, when none is given).
    pub authority: String,
}

/// Splits a `ws://` URL; `wss://` (TLS) and other schemes are refused in words.
///
/// ```
/// use posecov::input::log::ws::client::parse_url;
/// assert_eq!(parse_url("ws://127.0.0.1:8765").unwrap().authority, "127.0.0.1:8765");
/// assert_eq!(parse_url("ws://robot/").unwrap().authority, "robot:8765");
/// assert!(parse_url("wss://robot").unwrap_err().contains("TLS"));
/// ```
pub fn parse_url(url: &str) -> Result<WsUrl, String> {
    if url.starts_with("wss://") {
        return Err("wss:// (TLS) is not read: posecov connects to ws:// only (foxglove_bridge serves ws:// by default)".to_owned());
    }
    let rest = url
        .strip_prefix("ws://")
        .ok_or_else(|| "not a ws:// URL".to_owned())?;
    let host_port = rest.split(['/', '?', '#']).next().unwrap_or_default();
    if host_port.is_empty() {
        return Err("no host in the URL (ws://HOST:PORT)".to_owned());
    }
    let has_port = match host_port.rfind(':') {
        Some(i) => !host_port[i..].contains(']'),
        None => false,
    };
    Ok(WsUrl {
        url: url.to_owned(),
        authority: if has_port {
            host_port.to_owned()
        } else {
            format!("{host_port}:8765")
        },
    })
}

/// An open connection and the subprotocol the server chose.
pub struct Connection {
    /// The socket.
    pub socket: WebSocket<TcpStream>,
    /// `foxglove.sdk.v1` or `foxglove.websocket.v1`.
    pub subprotocol: String,
}

/// Connects to `url`: resolves the host, opens TCP within [`CONNECT_TIMEOUT`] and does the
/// handshake offering [`SUBPROTOCOLS`] within the same time. Errors say what failed.
pub fn connect(url: &WsUrl) -> Result<Connection, String> {
    let addrs: Vec<_> = url
        .authority
        .to_socket_addrs()
        .map_err(|e| format!("the host does not resolve ({e})"))?
        .collect();
    let mut last = None;
    let mut stream = None;
    for addr in &addrs {
        match TcpStream::connect_timeout(addr, CONNECT_TIMEOUT) {
            Ok(s) => {
                stream = Some(s);
                break;
            }
            Err(e) => last = Some(e),
        }
    }
    let stream = stream.ok_or_else(|| match last {
        Some(e) if e.kind() == ErrorKind::ConnectionRefused => {
            "connection refused (is foxglove_bridge running, on this port?)".to_owned()
        }
        Some(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => format!(
            "no answer within {} s (connect timeout)",
            CONNECT_TIMEOUT.as_secs()
        ),
        Some(e) => format!("cannot connect ({e})"),
        None => "the host resolves to no address".to_owned(),
    })?;
    let io = |e: std::io::Error| format!("cannot set up the connection ({e})");
    stream.set_read_timeout(Some(CONNECT_TIMEOUT)).map_err(io)?;
    stream
        .set_write_timeout(Some(CONNECT_TIMEOUT))
        .map_err(io)?;
    stream.set_nodelay(true).map_err(io)?;
    let mut request = url
        .url
        .as_str()
        .into_client_request()
        .map_err(|e| format!("not a WebSocket URL ({e})"))?;
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        HeaderValue::from_static("foxglove.sdk.v1, foxglove.websocket.v1"),
    );
    let config = WebSocketConfig::default()
        .max_frame_size(Some(MAX_FRAME))
        .max_message_size(Some(MAX_FRAME));
    let (socket, response) = match tungstenite::client::client_with_config(
        request,
        stream,
        Some(config),
    ) {
        Ok(done) => done,
        Err(HandshakeError::Interrupted(_)) => {
            return Err(format!(
                "the server accepted the connection but did not answer the WebSocket handshake within {} s",
                CONNECT_TIMEOUT.as_secs()
            ));
        }
        Err(HandshakeError::Failure(e)) => return Err(handshake_error(&e)),
    };
    let subprotocol = response
        .headers()
        .get("Sec-WebSocket-Protocol")
        .and_then(|v| v.to_str().ok())
        .unwrap_or_default()
        .trim()
        .to_owned();
    if !SUBPROTOCOLS.contains(&subprotocol.as_str()) {
        return Err(format!(
            "the server chose subprotocol `{subprotocol}`; posecov speaks {}",
            SUBPROTOCOLS.join(" and ")
        ));
    }
    socket.get_ref().set_read_timeout(Some(POLL)).map_err(io)?;
    Ok(Connection {
        socket,
        subprotocol,
    })
}

/// A failed handshake in words.
fn handshake_error(e: &tungstenite::Error) -> String {
    use tungstenite::error::{Error, ProtocolError, SubProtocolError};
    match e {
        Error::Http(response) => format!(
            "the server answered HTTP {} without upgrading to a WebSocket (not a Foxglove WebSocket server?)",
            response.status()
        ),
        Error::Protocol(ProtocolError::SecWebSocketSubProtocolError(
            SubProtocolError::NoSubProtocol | SubProtocolError::InvalidSubProtocol,
        )) => format!(
            "the server speaks none of the subprotocols posecov offers ({}): not a Foxglove WebSocket server",
            SUBPROTOCOLS.join(", ")
        ),
        Error::Io(io) if matches!(io.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
            format!(
                "the server accepted the connection but did not answer the WebSocket handshake within {} s",
                CONNECT_TIMEOUT.as_secs()
            )
        }
        Error::Protocol(ProtocolError::HandshakeIncomplete) => {
            "the server closed the connection during the WebSocket handshake".to_owned()
        }
        other => format!("the WebSocket handshake failed ({other})"),
    }
}

/// What one read gave.
pub enum Read {
    /// A frame.
    Frame(Message),
    /// Nothing within [`POLL`].
    Idle,
    /// The server closed the connection, with its reason.
    Closed(String),
}

/// Whether a read error only means "nothing yet": the read timeout passed, or a signal
/// (Ctrl-C) interrupted the wait.
fn waiting(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
    )
}

/// Reads one frame, waiting at most [`POLL`]. A frame beyond [`MAX_FRAME`] is an error (the
/// stream is refused); a broken connection or framing is [`Read::Closed`] (connected again).
pub fn read(socket: &mut WebSocket<TcpStream>) -> Result<Read, String> {
    use tungstenite::error::{CapacityError, Error};
    match socket.read() {
        Ok(Message::Close(frame)) => Ok(Read::Closed(match frame {
            Some(f) if !f.reason.is_empty() => format!("closed by the server: {}", f.reason),
            _ => "closed by the server".to_owned(),
        })),
        Ok(message) => Ok(Read::Frame(message)),
        // Nothing yet, or a signal (Ctrl-C) interrupted the wait: the caller looks again.
        Err(Error::Io(e)) if waiting(&e) => Ok(Read::Idle),
        Err(Error::ConnectionClosed | Error::AlreadyClosed) => {
            Ok(Read::Closed("closed by the server".to_owned()))
        }
        Err(Error::Protocol(tungstenite::error::ProtocolError::ResetWithoutClosingHandshake)) => {
            Ok(Read::Closed("the connection was reset".to_owned()))
        }
        Err(Error::Capacity(CapacityError::MessageTooLong { size, .. })) => Err(format!(
            "a frame of {size} bytes, beyond the {} MiB posecov accepts",
            MAX_FRAME >> 20
        )),
        Err(Error::Io(e)) => Ok(Read::Closed(format!("the connection was lost ({e})"))),
        // The framing itself is broken: this connection cannot be read on.
        Err(e) => Ok(Read::Closed(format!("a damaged WebSocket frame ({e})"))),
    }
}

/// Sends a text frame.
pub fn send(socket: &mut WebSocket<TcpStream>, text: String) -> Result<(), String> {
    socket
        .send(Message::text(text))
        .map_err(|e| format!("cannot send to the server ({e})"))
}

/// Closes the connection politely, waiting a little for the server's close (never long).
pub fn close(socket: &mut WebSocket<TcpStream>) {
    if socket.close(None).is_err() {
        return;
    }
    for _ in 0..10 {
        match socket.read() {
            Ok(_) => {}
            Err(tungstenite::Error::Io(e)) if waiting(&e) => {}
            Err(_) => return,
        }
    }
}
