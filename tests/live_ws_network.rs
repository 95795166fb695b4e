//! A running robot, live (issue 31): bad input from the network, each a clear message naming
//! the URL, never a panic or a hang, all on 127.0.0.1 — a closed port, a listener that never
//! answers, HTTP without an upgrade, another subprotocol, and a scripted server (tungstenite,
//! `foxglove.websocket.v1`) for what no real server sends: damaged frames, an oversize frame, a
//! connection dropped. The real servers: tests/live_ws.rs.

use std::io::{Read as _, Write as _};
use std::net::TcpListener;
use std::time::{Duration, Instant};

mod ws_run;
use ws_run::{posecov, text};

// ---------------------------------------------------------------------------------------
// Bad input from the network: each a clear message naming the URL, exit 2, no hang.

fn refused_with(url: &str, words: &str) {
    let started = Instant::now();
    let out = posecov(&["check", url, "--duration", "30s"]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(said.contains(&format!("error: {url}: ")), "{said}");
    assert!(said.contains(words), "{said}");
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "no hang: {said}"
    );
}

/// A port nothing listens on (bound, then closed).
fn closed_port() -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    listener.local_addr().expect("addr").port()
}

/// Serves one connection on a thread with `serve`; returns the port.
fn one_shot(serve: impl FnOnce(std::net::TcpStream) + Send + 'static) -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let port = listener.local_addr().expect("addr").port();
    std::thread::spawn(move || {
        if let Ok((stream, _)) = listener.accept() {
            serve(stream);
        }
    });
    port
}

#[test]
fn a_closed_port_is_connection_refused() {
    refused_with(
        &format!("ws://127.0.0.1:{}", closed_port()),
        "connection refused",
    );
}

#[test]
fn a_listener_that_never_answers_times_out() {
    let port = one_shot(|stream| {
        std::thread::sleep(Duration::from_secs(15));
        drop(stream);
    });
    refused_with(
        &format!("ws://127.0.0.1:{port}"),
        "accepted the connection but did not answer the WebSocket handshake within 5 s",
    );
}

#[test]
fn http_without_upgrade_is_named() {
    let port = one_shot(|mut stream| {
        let mut buf = [0u8; 4096];
        let _ = stream.read(&mut buf);
        let _ = stream
            .write_all(b"HTTP/1.1 200 OK\r\nContent-Length: 2\r\nConnection: close\r\n\r\nhi");
    });
    refused_with(
        &format!("ws://127.0.0.1:{port}"),
        "answered HTTP 200 OK without upgrading to a WebSocket",
    );
}

#[test]
fn a_subprotocol_posecov_does_not_speak_is_named() {
    let port = one_shot(|stream| {
        if let Some(mut ws) = accept_as(stream, "rosbridge.v2") {
            let _ = ws.read();
        }
    });
    refused_with(
        &format!("ws://127.0.0.1:{port}"),
        "the server speaks none of the subprotocols posecov offers (foxglove.sdk.v1, foxglove.websocket.v1)",
    );
}

#[test]
fn a_name_that_does_not_resolve_and_wss_are_said() {
    refused_with(
        "ws://no-such-host.invalid:8765",
        "the host does not resolve",
    );
    refused_with("wss://127.0.0.1:8765", "wss:// (TLS) is not read");
}

#[test]
fn live_flags_on_a_log_file_are_refused() {
    let out = posecov(&["check", "covariance_health", "--messages", "5"]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(
        said.contains("--messages 5: applies to a live stream (ws://HOST:PORT) only"),
        "{said}"
    );
}

// ---------------------------------------------------------------------------------------
// A scripted server (tungstenite, `foxglove.websocket.v1`) for what no real server sends:
// damaged frames, an oversize frame, a connection dropped.

type Ws = tungstenite::WebSocket<std::net::TcpStream>;

/// Accepts a WebSocket handshake on `stream`, the server choosing `subprotocol`.
#[allow(clippy::result_large_err)] // tungstenite's callback type: its error is an HTTP response
fn accept_as(stream: std::net::TcpStream, subprotocol: &'static str) -> Option<Ws> {
    use tungstenite::handshake::server::{ErrorResponse, Request, Response};
    let answer = move |_: &Request, mut response: Response| -> Result<Response, ErrorResponse> {
        let v = subprotocol.parse().expect("header");
        response.headers_mut().insert("Sec-WebSocket-Protocol", v);
        Ok(response)
    };
    tungstenite::accept_hdr(stream, answer).ok()
}

/// Serves `sessions` connections in turn on 127.0.0.1: each advertises `/pose` (ROS 2
/// PoseWithCovarianceStamped, `cdr`), waits for the client's `subscribe` and runs
/// `script(ws, subscription id, session)`. The listener closes as the last session starts (a
/// client connecting again is then refused). Returns the port.
fn scripted(sessions: u32, script: impl Fn(&mut Ws, u32, u32) + Send + 'static) -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let port = listener.local_addr().expect("addr").port();
    std::thread::spawn(move || {
        let mut listener = Some(listener);
        for session in 0..sessions {
            let Some(Ok((stream, _))) = listener.as_ref().map(TcpListener::accept) else {
                return;
            };
            if session + 1 == sessions {
                listener = None;
            }
            let Some(mut ws) = accept_as(stream, "foxglove.websocket.v1") else {
                return;
            };
            let advertise = r#"{"op":"advertise","channels":[{"id":1,"topic":"/pose","encoding":"cdr","schemaName":"geometry_msgs/msg/PoseWithCovarianceStamped","schema":"","schemaEncoding":"ros2msg"}]}"#;
            ws.send(tungstenite::Message::text(advertise))
                .expect("advertise");
            let subscription = loop {
                match ws.read() {
                    Ok(tungstenite::Message::Text(t)) if t.contains("\"subscribe\"") => {
                        let v: serde_json::Value = serde_json::from_str(&t).expect("json");
                        break v["subscriptions"][0]["id"].as_u64().expect("id") as u32;
                    }
                    Ok(_) => {}
                    Err(_) => return,
                }
            };
            script(&mut ws, subscription, session);
        }
    });
    port
}

/// A message-data frame of message `i` on `subscription`: a PoseWithCovarianceStamped in
/// CDR (written here, field by field), driving 0.1 m a message with σ growing.
fn pose_frame(subscription: u32, i: u32) -> tungstenite::Message {
    let mut frame = vec![1u8];
    frame.extend(subscription.to_le_bytes());
    frame.extend((u64::from(i) * 100_000_000).to_le_bytes());
    frame.extend([0, 1, 0, 0]); // CDR, little endian
    frame.extend((100 + i as i32).to_le_bytes());
    frame.extend(0u32.to_le_bytes());
    frame.extend(4u32.to_le_bytes());
    frame.extend(b"map\0");
    let s = 0.01 * f64::from(1 + i);
    let mut covariance = [0.0; 36];
    for (axis, v) in [s, s, 1e-6, 1e-4, 1e-4, s].into_iter().enumerate() {
        covariance[7 * axis] = v;
    }
    let pose = [0.1 * f64::from(i), 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    for v in pose.iter().chain(&covariance) {
        frame.extend(v.to_le_bytes());
    }
    tungstenite::Message::binary(frame)
}

/// Reads until the client goes (its unsubscribe and close), so that nothing is cut short.
fn until_gone(ws: &mut Ws) {
    while ws.read().is_ok() {}
}

#[test]
fn damaged_frames_are_skipped_and_said_and_the_run_goes_on() {
    let port = scripted(1, |ws, sub, _| {
        use tungstenite::Message;
        ws.send(Message::text("{\"op\":")).expect("send");
        ws.send(Message::text(r#"{"op":"advertise"}"#))
            .expect("send");
        let mut unknown = vec![1u8];
        unknown.extend((sub + 40).to_le_bytes());
        unknown.extend([0; 8]);
        ws.send(Message::binary(unknown)).expect("send");
        ws.send(Message::binary(vec![1u8, 2, 3])).expect("send");
        for i in 0..10 {
            ws.send(pose_frame(sub, i)).expect("send");
        }
        until_gone(ws);
    });
    let url = format!("ws://127.0.0.1:{port}");
    let out = posecov(&["check", &url, "--messages", "10", "--duration", "20s"]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(
        said.contains(": ok (1 pose topic(s), 10 messages"),
        "{said}"
    );
    let warning = format!("warning: {url}: skipped 4 damaged frame(s), the run went on: ");
    assert!(said.contains(&warning), "{said}");
    for words in [
        "a text frame: malformed JSON",
        "a text frame: `advertise` without its \"channels\" field",
        "which posecov never made",
        "a truncated message-data frame (3 bytes",
    ] {
        assert!(said.contains(words), "{words}: {said}");
    }
}

#[test]
fn an_oversize_frame_ends_the_read_naming_the_bound() {
    let port = scripted(1, |ws, _, _| {
        // A binary frame header stating 17 MiB (the payload never comes).
        let mut header = vec![0x82u8, 127];
        header.extend((17u64 << 20).to_be_bytes());
        let _ = ws.get_mut().write_all(&header);
        until_gone(ws);
    });
    let url = format!("ws://127.0.0.1:{port}");
    refused_with(
        &url,
        "a frame of 17825792 bytes, beyond the 16 MiB posecov accepts",
    );
}

#[test]
fn a_lost_connection_is_made_again_and_said() {
    // Two connections of 5 messages each, the first dropped without a close.
    let port = scripted(2, |ws, sub, session| {
        for i in 5 * session..5 * session + 5 {
            ws.send(pose_frame(sub, i)).expect("send");
        }
        if session == 1 {
            until_gone(ws);
        }
    });
    let url = format!("ws://127.0.0.1:{port}");
    let out = posecov(&["check", &url, "--messages", "10", "--duration", "30s"]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(0), "{said}");
    assert!(
        said.contains(": ok (1 pose topic(s), 10 messages"),
        "{said}"
    );
    assert!(
        said.contains(&format!(
            "warning: {url}: the connection was lost 1 time(s) and made again"
        )),
        "{said}"
    );
}

#[test]
fn a_stream_that_ends_early_is_exit_2_with_the_reason() {
    let port = scripted(1, |ws, sub, _| {
        for i in 0..5 {
            ws.send(pose_frame(sub, i)).expect("send");
        }
        let _ = ws.close(None);
        let _ = ws.flush();
    });
    let url = format!("ws://127.0.0.1:{port}");
    let out = posecov(&["check", &url, "--messages", "10", "--duration", "30s"]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(said.contains(&format!("error: {url}: ")) && said.contains("the stream ended early: closed by the server; connecting again failed 4 time(s) (last: connection refused"), "{said}");
    assert!(
        said.contains("5 message(s), before --messages 10"),
        "{said}"
    );
}

/// `frame` (a [`pose_frame`]) with its covariance's first number NaN.
fn with_nan(frame: tungstenite::Message) -> tungstenite::Message {
    let mut bytes = frame.into_data().to_vec();
    // 13 (message data) + 4 (CDR) + 8 (stamp) + 8 ("map") + 56 (pose).
    bytes[89..97].copy_from_slice(&f64::NAN.to_le_bytes());
    tungstenite::Message::binary(bytes)
}

#[test]
fn bad_channels_and_messages_are_named_or_counted() {
    let port = scripted(1, |ws, sub, _| {
        use tungstenite::Message;
        // A pose schema in an encoding posecov does not read, and a schema it does not know.
        let more = r#"{"op":"advertise","channels":[{"id":2,"topic":"/pose_json","encoding":"json","schemaName":"geometry_msgs/msg/PoseWithCovarianceStamped","schema":""},{"id":3,"topic":"/widget","encoding":"cdr","schemaName":"acme_msgs/msg/Widget","schema":""}]}"#;
        ws.send(Message::text(more)).expect("send");
        for i in 0..5 {
            ws.send(pose_frame(sub, i)).expect("send");
        }
        // A CDR payload cut short, a NaN covariance, a stamp out of order.
        let mut cut = pose_frame(sub, 5).into_data().to_vec();
        cut.truncate(50);
        ws.send(Message::binary(cut)).expect("send");
        ws.send(with_nan(pose_frame(sub, 6))).expect("send");
        ws.send(pose_frame(sub, 2)).expect("send");
        until_gone(ws);
    });
    let url = format!("ws://127.0.0.1:{port}");
    let out = posecov(&[
        "report",
        &url,
        "--json",
        "--messages",
        "8",
        "--duration",
        "20s",
    ]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(0), "{said}");
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let skipped = json["skipped"].to_string();
    assert!(
        skipped.contains(r#""name":"/pose_json""#)
            && skipped.contains("in json encoding; posecov reads cdr or ros1"),
        "{skipped}"
    );
    assert!(
        skipped.contains(r#""message_type":"acme_msgs/msg/Widget""#),
        "{skipped}"
    );
    let health = &json["topics"][0]["health"];
    for (issue, count) in [("undecodable", 1), ("non_finite", 1), ("stamp_order", 1)] {
        assert_eq!(health[issue]["count"], count, "{issue}: {health}");
    }
    assert_eq!(json["topics"][0]["messages"], 8);
}

#[test]
fn a_flood_is_read_or_thinned_and_the_count_thinned_is_said() {
    const SENT: u32 = 40_000;
    let port = scripted(1, |ws, sub, _| {
        for i in 0..SENT {
            if ws.send(pose_frame(sub, i)).is_err() {
                return;
            }
        }
        until_gone(ws);
    });
    let url = format!("ws://127.0.0.1:{port}");
    let out = posecov(&[
        "report",
        &url,
        "--json",
        "--messages",
        &SENT.to_string(),
        "--duration",
        "300s",
    ]);
    let said = text(&out);
    assert_eq!(out.status.code(), Some(0), "{said}");
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let read = json["topics"][0]["messages"].as_u64().expect("messages");
    let thinned = json["meta"]["stream"]["thinned"]
        .as_u64()
        .expect("meta.stream.thinned");
    // Every message sent was read or thinned (and said so: `StreamNotes::thin`), none twice.
    assert_eq!(read + thinned, u64::from(SENT), "{said}");
}
