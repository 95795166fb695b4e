//! The web viewer through the page's own server (same origin). The viewer's servers — its
//! files and its gRPC-web stream — stay on loopback; the page forwards to them, so a machine
//! that reaches the page (`--bind` beyond loopback: a tablet in a lecture hall) gets the
//! viewer too, under the page's own `Host`/`Origin` checks.
//!
//! | page path | forwarded to |
//! |---|---|
//! | `/viewer/…` | the web viewer's files (`/…` on its loopback port) |
//! | `/rerun.…/…` (gRPC-web, `POST`) | the viewer's gRPC server on loopback |
//!
//! The page hands the viewer `?url=rerun+http://<the page's host>/proxy`, so the viewer in
//! the browser asks the page for its stream.

use std::net::SocketAddr;

use axum::body::{Body, Bytes};
use axum::http::{HeaderMap, HeaderValue, Method, Request, StatusCode, header};
use axum::response::Response;

/// Where the viewer's own servers listen (loopback).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Upstream {
    /// The web viewer's files.
    pub web: SocketAddr,
    /// The gRPC server the viewer reads its stream from.
    pub grpc: SocketAddr,
}

/// The page's path of the web viewer (its files below it).
pub const VIEWER_PATH: &str = "/viewer/";

/// Where a request for `path_and_query` goes when it is the viewer's: its files (below
/// [`VIEWER_PATH`], the prefix taken off) or its gRPC-web service paths (`/rerun.…`).
pub(super) fn target(upstream: &Upstream, path_and_query: &str) -> Option<(SocketAddr, String)> {
    if let Some(rest) = path_and_query.strip_prefix(VIEWER_PATH) {
        return Some((upstream.web, format!("/{rest}")));
    }
    path_and_query
        .starts_with("/rerun.")
        .then(|| (upstream.grpc, path_and_query.to_owned()))
}

/// Whether `path` is one the page forwards ([`target`]'s paths).
pub(super) fn is_viewer_path(path: &str) -> bool {
    path.starts_with(VIEWER_PATH) || path.starts_with("/rerun.")
}

/// Headers that belong to one connection (RFC 9110 §7.6.1), never forwarded; `Host` and
/// `Origin` are the page's, checked already: the loopback servers get their own.
const NOT_FORWARDED: [header::HeaderName; 8] = [
    header::CONNECTION,
    header::HOST,
    header::ORIGIN,
    header::REFERER,
    header::TRANSFER_ENCODING,
    header::UPGRADE,
    header::TE,
    header::PROXY_AUTHORIZATION,
];

/// Forwards one request to `to` (loopback) and streams the answer back; 502 with the reason
/// when the viewer's server cannot be reached.
pub(super) async fn forward(
    to: SocketAddr,
    path: String,
    method: Method,
    headers: &HeaderMap,
    body: Bytes,
) -> Response {
    match try_forward(to, path, method, headers, body).await {
        Ok(response) => response,
        Err(why) => {
            let mut r = Response::new(Body::from(
                serde_json::json!({ "error": format!("the viewer's server ({to}): {why}") })
                    .to_string(),
            ));
            *r.status_mut() = StatusCode::BAD_GATEWAY;
            r.headers_mut().insert(
                header::CONTENT_TYPE,
                HeaderValue::from_static("application/json"),
            );
            r
        }
    }
}

async fn try_forward(
    to: SocketAddr,
    path: String,
    method: Method,
    headers: &HeaderMap,
    body: Bytes,
) -> Result<Response, String> {
    let stream = tokio::net::TcpStream::connect(to)
        .await
        .map_err(|e| e.to_string())?;
    let (mut sender, connection) =
        hyper::client::conn::http1::handshake(hyper_util::rt::TokioIo::new(stream))
            .await
            .map_err(|e| e.to_string())?;
    // Runs the connection until the answer's body is done (a stream: as long as it is read).
    tokio::spawn(connection);
    let mut request = Request::builder()
        .method(method)
        .uri(path)
        .header(header::HOST, to.to_string());
    for (name, value) in headers {
        if !NOT_FORWARDED.contains(name) && name.as_str() != "keep-alive" {
            request = request.header(name, value);
        }
    }
    let request = request.body(Body::from(body)).map_err(|e| e.to_string())?;
    let response = sender
        .send_request(request)
        .await
        .map_err(|e| e.to_string())?;
    let (mut parts, incoming) = response.into_parts();
    for name in [header::CONNECTION, header::TRANSFER_ENCODING] {
        parts.headers.remove(name);
    }
    Ok(Response::from_parts(parts, Body::new(incoming)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_viewers_files_and_stream_go_to_loopback() {
        let up = Upstream {
            web: "127.0.0.1:9090".parse().unwrap(),
            grpc: "127.0.0.1:9876".parse().unwrap(),
        };
        assert_eq!(
            target(&up, "/viewer/re_viewer.js"),
            Some((up.web, "/re_viewer.js".into()))
        );
        assert_eq!(
            target(&up, "/viewer/?url=x"),
            Some((up.web, "/?url=x".into()))
        );
        let grpc = "/rerun.sdk_comms.v1alpha1.MessageProxyService/ReadMessages";
        assert_eq!(target(&up, grpc), Some((up.grpc, grpc.into())));
        assert_eq!(target(&up, "/api/state"), None);
        assert_eq!(target(&up, "/viewer"), None);
    }
}
