// ledge's glue between the browser and the client's wasm build: a
// miniquad plugin (miniquad's gl.js loads the wasm and calls
// `register_plugin` with its imports) giving the game the page's clock,
// the address's parameters, its connection to the server, files fetched
// from that server (a replay and its level), and a place to publish its
// state.
//
// The wasm checks the glue's version through `ledge_crate_version`
// (miniquad's loader logs a mismatch): keep GLUE_VERSION equal to
// `GLUE_VERSION` in client/src/bin/ledge-client/page.rs.
"use strict";

(function () {
    const GLUE_VERSION = 2;
    const decoder = new TextDecoder("utf-8");
    const encoder = new TextEncoder();

    // `wasm_memory` is gl.js's global, set once the module is instantiated.
    function bytes(ptr, len) {
        return new Uint8Array(wasm_memory.buffer, ptr, len);
    }

    // ---- The connection to the server that served this page ----------
    //
    // One session at a time: WebTransport when the browser has it and the
    // server offers it (/web.json), else (or if it cannot connect) a
    // WebSocket. Everything that arrives is queued as messages the game
    // takes with `ledge_net_poll`, one tag byte then the payload:
    //   0x00 control stream bytes, 0x01 a datagram, 0x02 level stream
    //   bytes, 0x03 level stream end (the WebSocket framing of
    //   shared/src/protocol/web.rs: a WebSocket message is passed as is);
    //   0xF0 opened (payload: the transport's name), 0xF1 closed (u32 LE
    //   close code, 0xFFFFFFFF if none, then the reason), 0xF2 failed
    //   (the reason).
    const TAG_STREAM = 0x00, TAG_DATAGRAM = 0x01, TAG_LEVEL = 0x02, TAG_LEVEL_END = 0x03;
    const TAG_OPENED = 0xF0, TAG_CLOSED = 0xF1, TAG_FAILED = 0xF2;
    // Messages waiting for the game; beyond this the connection is
    // dropped (the game stopped taking them).
    const MAX_QUEUE = 4096;
    // Datagrams waiting for WebTransport's writer; more are dropped.
    const MAX_DATAGRAM_BACKLOG = 8;
    const net = {
        queue: [],
        kind: null,        // "webtransport" | "websocket"
        ws: null,
        wt: null,
        stream: null,      // WebTransport control stream writer
        datagrams: null,   // WebTransport datagram writer
        backlog: 0,
        ended: false,
    };
    window.ledgeNet = net;

    function push(tag, payload) {
        if (net.queue.length >= MAX_QUEUE) {
            end(TAG_FAILED, "the game fell behind the network (" + MAX_QUEUE + " messages queued)");
            return;
        }
        const m = new Uint8Array(1 + payload.length);
        m[0] = tag;
        m.set(payload, 1);
        net.queue.push(m);
    }

    function end(tag, reason, code) {
        if (net.ended) {
            return;
        }
        net.ended = true;
        const text = encoder.encode(reason);
        if (tag === TAG_CLOSED) {
            const m = new Uint8Array(4 + text.length);
            new DataView(m.buffer).setUint32(0, code === undefined || code === null ? 0xFFFFFFFF : code >>> 0, true);
            m.set(text, 4);
            net.queue.push(Uint8Array.of(tag, ...m));
        } else {
            net.queue.push(Uint8Array.of(tag, ...text));
        }
        try { if (net.ws) net.ws.close(1000); } catch (e) { }
        try { if (net.wt) net.wt.close(); } catch (e) { }
    }

    function hexToBytes(hex) {
        const out = new Uint8Array(hex.length / 2);
        for (let i = 0; i < out.length; i++) {
            out[i] = parseInt(hex.substr(2 * i, 2), 16);
        }
        return out;
    }

    async function readAll(reader, onChunk) {
        for (;;) {
            const { value, done } = await reader.read();
            if (done) {
                return;
            }
            onChunk(value);
        }
    }

    async function openWebTransport(config) {
        const wt = config.webtransport;
        const url = "https://" + location.hostname + ":" + wt.port + wt.path;
        const transport = new WebTransport(url, {
            serverCertificateHashes: wt.cert_sha256.map(h => ({ algorithm: "sha-256", value: hexToBytes(h) })),
        });
        await transport.ready;
        net.wt = transport;
        const bidi = await transport.createBidirectionalStream();
        net.stream = bidi.writable.getWriter();
        net.datagrams = transport.datagrams.writable.getWriter();
        net.kind = "webtransport";
        push(TAG_OPENED, encoder.encode("WebTransport"));
        readAll(bidi.readable.getReader(), chunk => push(TAG_STREAM, chunk)).catch(() => { });
        readAll(transport.datagrams.readable.getReader(), d => push(TAG_DATAGRAM, d)).catch(() => { });
        (async () => {
            const streams = transport.incomingUnidirectionalStreams.getReader();
            for (;;) {
                const { value, done } = await streams.read();
                if (done) {
                    return;
                }
                readAll(value.getReader(), chunk => push(TAG_LEVEL, chunk))
                    .then(() => push(TAG_LEVEL_END, new Uint8Array(0)))
                    .catch(() => { });
            }
        })().catch(() => { });
        transport.closed
            .then(info => end(TAG_CLOSED, info.reason || "", info.closeCode))
            .catch(e => end(TAG_FAILED, "the WebTransport session broke: " + e));
    }

    function openWebSocket(config) {
        return new Promise((resolve, reject) => {
            const scheme = location.protocol === "https:" ? "wss://" : "ws://";
            const ws = new WebSocket(scheme + location.host + config.websocket);
            ws.binaryType = "arraybuffer";
            let opened = false;
            ws.onopen = () => {
                opened = true;
                net.ws = ws;
                net.kind = "websocket";
                push(TAG_OPENED, encoder.encode("WebSocket"));
                resolve();
            };
            ws.onmessage = event => {
                if (event.data instanceof ArrayBuffer && event.data.byteLength > 0) {
                    const m = new Uint8Array(event.data);
                    push(m[0], m.subarray(1));
                }
            };
            ws.onclose = event => {
                if (!opened) {
                    reject(new Error("the WebSocket did not open (code " + event.code + ")"));
                } else {
                    end(TAG_CLOSED, event.reason || "", event.code >= 4000 && event.code < 5000 ? event.code - 4000 : null);
                }
            };
            ws.onerror = () => { };
        });
    }

    // ---- Files from the server that served this page ------------------
    //
    // `ledge_fetch_start` starts one (a replay, a level bundle) with a
    // bound on its body: a larger Content-Length is refused before the
    // body is read, and the body is never read past the bound. The game
    // polls it (`ledge_fetch_poll`), then takes its bytes
    // (`ledge_fetch_take`), which forgets it. An HTTP error keeps the
    // server's text (at most MAX_FETCH_TEXT bytes); no answer at all
    // (status 0) keeps why, as text.
    const MAX_FETCH_TEXT = 4096;
    const fetches = new Map();
    let nextFetch = 1;

    async function readBounded(response, limit) {
        const chunks = [];
        let total = 0;
        let over = false;
        if (response.body) {
            const reader = response.body.getReader();
            for (;;) {
                const { value, done } = await reader.read();
                if (done) {
                    break;
                }
                if (total + value.length > limit) {
                    chunks.push(value.subarray(0, limit - total));
                    total = limit;
                    over = true;
                    reader.cancel().catch(() => { });
                    break;
                }
                chunks.push(value);
                total += value.length;
            }
        }
        const body = new Uint8Array(total);
        let at = 0;
        for (const c of chunks) {
            body.set(c, at);
            at += c.length;
        }
        return { body, over };
    }

    async function fetchBounded(path, max) {
        const failed = why => ({ status: 0, body: encoder.encode(why), retryAfter: 0xFFFFFFFF });
        let response;
        try {
            response = await fetch(path, { cache: "no-cache" });
        } catch (e) {
            return failed("the server cannot be reached (" + e.message + "): is it running? reload the page to try again");
        }
        const retry = parseInt(response.headers.get("Retry-After") || "", 10);
        const retryAfter = Number.isFinite(retry) && retry >= 0 ? Math.min(retry, 0xFFFFFFFE) : 0xFFFFFFFF;
        if (!response.ok) {
            const { body } = await readBounded(response, MAX_FETCH_TEXT);
            return { status: response.status, body, retryAfter };
        }
        const length = Number(response.headers.get("Content-Length"));
        if (Number.isFinite(length) && length > max) {
            try { response.body && response.body.cancel(); } catch (e) { }
            return failed("the server offers " + length + " bytes, more than it can be (" + max + " bytes): refused without reading it");
        }
        const { body, over } = await readBounded(response, max);
        if (over) {
            return failed("the server sent more than it can be (" + max + " bytes): refused; is this a ledge server?");
        }
        return { status: response.status, body, retryAfter };
    }

    async function connect() {
        let config;
        try {
            const response = await fetch("web.json", { cache: "no-store" });
            if (!response.ok) {
                throw new Error("HTTP " + response.status);
            }
            config = await response.json();
        } catch (e) {
            end(TAG_FAILED, "cannot read the server's web.json (" + e.message + "): is this page served by ledge-server --web-bind?");
            return;
        }
        const wanted = new URLSearchParams(location.search).get("transport");
        const canWebTransport = typeof WebTransport === "function" && config.webtransport && wanted !== "websocket";
        if (canWebTransport) {
            try {
                await openWebTransport(config);
                return;
            } catch (e) {
                console.warn("ledge: WebTransport failed (" + e + "); trying a WebSocket");
                net.wt = null;
            }
        }
        try {
            await openWebSocket(config);
        } catch (e) {
            end(TAG_FAILED, "cannot connect to the server: " + e.message);
        }
    }

    miniquad_add_plugin({
        name: "ledge",
        version: GLUE_VERSION,
        register_plugin: function (importObject) {
            const env = importObject.env;
            // Milliseconds since the page loaded, monotonic.
            env.ledge_now_ms = function () {
                return performance.now();
            };
            // The address's parameter `name`, decoded, as UTF-8 into
            // `out` (at most `cap` bytes); its length, or -1 if absent.
            env.ledge_page_param = function (namePtr, nameLen, out, cap) {
                const name = decoder.decode(bytes(namePtr, nameLen));
                const value = new URLSearchParams(window.location.search).get(name);
                if (value === null) {
                    return -1;
                }
                const encoded = encoder.encode(value);
                const n = Math.min(encoded.length, cap);
                bytes(out, n).set(encoded.subarray(0, n));
                return n;
            };
            // The page's host (HOST:PORT) as UTF-8 into `out` (at most `cap`
            // bytes); its length.
            env.ledge_page_host = function (out, cap) {
                const encoded = encoder.encode(location.host);
                const n = Math.min(encoded.length, cap);
                bytes(out, n).set(encoded.subarray(0, n));
                return n;
            };
            // The gamepads (standard mapping) into `out`, 12 bytes each: the
            // pressed buttons' bits (u32 LE), the left stick's x and y (f32
            // LE); returns the bytes written.
            env.ledge_gamepads = function (out, cap) {
                const pads = navigator.getGamepads ? navigator.getGamepads() : [];
                const view = new DataView(wasm_memory.buffer);
                let n = 0;
                for (const pad of pads) {
                    if (!pad || !pad.connected || pad.mapping !== "standard" || n + 12 > cap) {
                        continue;
                    }
                    let bits = 0;
                    for (let i = 0; i < Math.min(pad.buttons.length, 32); i++) {
                        if (pad.buttons[i].pressed) {
                            bits |= 1 << i;
                        }
                    }
                    view.setUint32(out + n, bits >>> 0, true);
                    view.setFloat32(out + n + 4, pad.axes[0] || 0, true);
                    view.setFloat32(out + n + 8, pad.axes[1] || 0, true);
                    n += 12;
                }
                return n;
            };
            // Starts connecting to the server that served the page.
            env.ledge_net_open = function () {
                connect();
            };
            // The next message (tag byte, payload) into `out` (at most `cap`
            // bytes): its length, or -1 if none. A longer stream or level
            // chunk is split; a longer datagram is dropped.
            env.ledge_net_poll = function (out, cap) {
                while (net.queue.length > 0) {
                    let m = net.queue[0];
                    if (m.length > cap) {
                        if (m[0] === TAG_STREAM || m[0] === TAG_LEVEL) {
                            const rest = new Uint8Array(1 + m.length - cap);
                            rest[0] = m[0];
                            rest.set(m.subarray(cap), 1);
                            net.queue[0] = rest;
                            m = m.subarray(0, cap);
                        } else {
                            net.queue.shift();
                            continue;
                        }
                    } else {
                        net.queue.shift();
                    }
                    bytes(out, m.length).set(m);
                    return m.length;
                }
                return -1;
            };
            // Sends `len` bytes at `ptr`: on the control stream (kind 0) or
            // as a datagram (kind 1). Returns 0 if dropped.
            env.ledge_net_send = function (kind, ptr, len) {
                if (net.ended) {
                    return 0;
                }
                const payload = bytes(ptr, len).slice();
                if (net.kind === "websocket") {
                    if (kind === TAG_DATAGRAM && net.ws.bufferedAmount > 65536) {
                        return 0;
                    }
                    const m = new Uint8Array(1 + len);
                    m[0] = kind;
                    m.set(payload, 1);
                    net.ws.send(m);
                    return 1;
                }
                if (net.kind === "webtransport") {
                    if (kind === TAG_STREAM) {
                        net.stream.write(payload).catch(e => end(TAG_FAILED, "writing to the server failed: " + e));
                        return 1;
                    }
                    if (net.backlog >= MAX_DATAGRAM_BACKLOG) {
                        return 0;
                    }
                    net.backlog++;
                    net.datagrams.write(payload).then(() => net.backlog--, () => net.backlog--);
                    return 1;
                }
                return 0;
            };
            // Starts fetching `path` (UTF-8 at pathPtr) from this page's
            // server, a body of at most `max` bytes; returns its handle.
            env.ledge_fetch_start = function (pathPtr, pathLen, max) {
                const path = decoder.decode(bytes(pathPtr, pathLen));
                const handle = nextFetch++;
                const entry = { done: null };
                fetches.set(handle, entry);
                fetchBounded(path, max >>> 0)
                    .catch(e => ({ status: 0, body: encoder.encode("the download broke off (" + e + "): reload the page to try again"), retryAfter: 0xFFFFFFFF }))
                    .then(done => { entry.done = done; });
                return handle;
            };
            // -1 while fetch `handle` runs; else 0, with its status, body
            // length and Retry-After (u32 LE each) at `info`.
            env.ledge_fetch_poll = function (handle, info) {
                const entry = fetches.get(handle);
                if (!entry) {
                    const view = new DataView(wasm_memory.buffer);
                    view.setUint32(info, 0, true);
                    view.setUint32(info + 4, 0, true);
                    view.setUint32(info + 8, 0xFFFFFFFF, true);
                    return 0;
                }
                if (!entry.done) {
                    return -1;
                }
                const view = new DataView(wasm_memory.buffer);
                view.setUint32(info, entry.done.status >>> 0, true);
                view.setUint32(info + 4, entry.done.body.length >>> 0, true);
                view.setUint32(info + 8, entry.done.retryAfter >>> 0, true);
                return 0;
            };
            // Copies fetch `handle`'s body into `out` (at most `cap` bytes)
            // and forgets it; the bytes copied.
            env.ledge_fetch_take = function (handle, out, cap) {
                const entry = fetches.get(handle);
                fetches.delete(handle);
                if (!entry || !entry.done) {
                    return 0;
                }
                const n = Math.min(entry.done.body.length, cap >>> 0);
                if (n > 0) {
                    bytes(out, n).set(entry.done.body.subarray(0, n));
                }
                return n;
            };
            // The game's state (JSON) as `window.ledgeState`.
            env.ledge_report = function (ptr, len) {
                try {
                    window.ledgeState = JSON.parse(decoder.decode(bytes(ptr, len)));
                } catch (e) {
                    console.error("ledge: bad state report: " + e);
                }
            };
        },
    });
})();
