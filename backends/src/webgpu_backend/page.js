// strata's WebGPU bridge: the page the `webgpu` backend opens in headless Chromium.
// Written for strata (backends/src/webgpu_backend/), served from the backend's own
// loopback server under a random token, never from anywhere else.
//
// The page holds the GPUDevice (executor.js runs each message on it). It asks the server
// for work with one POST to `exchange` whose body is its answer to the previous message
// and whose response is the next message (a long poll: the server answers when the Rust
// side has a call to make).
import { frame, run, unframe } from './executor.js';

async function main() {
  let answer = { header: { ready: true }, parts: [] };
  for (;;) {
    let response;
    try {
      response = await fetch('exchange', {
        method: 'POST',
        headers: { 'Content-Type': 'application/octet-stream' },
        body: frame(answer.header, answer.parts),
        cache: 'no-store',
      });
    } catch (error) {
      return; // The backend is gone.
    }
    if (!response.ok) return;
    const message = unframe(await response.arrayBuffer());
    if (message.header.close) return;
    answer = await run(message);
  }
}

main();
