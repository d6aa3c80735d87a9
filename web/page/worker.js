// worker.js: runs strata's live comparison (strata_web.wasm, built from web/src/) in a
// worker, which may block. Written for strata (web/page/, MIT OR Apache-2.0).
//
// The module is strata's renderer compiled to WebAssembly; its WebGPU backend hands each
// message to `exchange` below, which posts it to the page's thread (where the GPUDevice
// lives and executor.js runs it) and waits with Atomics.wait until the answer is in the
// shared buffer. Between frames the worker yields (setTimeout) so that the page's
// messages (denoiser on or off, pause) reach it.

const NO_ANSWER = 0xFFFFFFFF;
let exports = null;
// Int32Array: [0] 0 waiting, 1 answered, 2 the page failed; [1] the answer's length;
// [2] the exchange it answers (an answer to an earlier one, which timed out, is not taken).
let control = null;
let exchanges = 0;
let answers = null; // SharedArrayBuffer (growable) holding the answer
let denoise = false;
let paused = false;
let lastFrame = 0;
let maxFrames = 0;
let denoiseFrom = 0;
let queued = false;

const decoder = new TextDecoder();

function memory() {
  return exports.memory.buffer;
}

function report() {
  const bytes = new Uint8Array(memory(), exports.strata_web_report_ptr() >>> 0, exports.strata_web_report_len() >>> 0);
  return JSON.parse(decoder.decode(bytes));
}

const imports = {
  strata_webgpu: {
    exchange(pointer, length, timeoutMs) {
      // Addresses and lengths arrive as signed 32-bit numbers: `>>> 0` reads them unsigned.
      const message = new Uint8Array(memory(), pointer >>> 0, length >>> 0).slice();
      const id = ++exchanges;
      Atomics.store(control, 0, 0);
      postMessage({ kind: 'exchange', message, id }, [message.buffer]);
      const outcome = Atomics.wait(control, 0, 0, timeoutMs >>> 0);
      if (outcome === 'timed-out' || Atomics.load(control, 0) !== 1 || Atomics.load(control, 2) !== id) {
        return NO_ANSWER;
      }
      return Atomics.load(control, 1);
    },
    take_answer(pointer, length) {
      new Uint8Array(memory(), pointer >>> 0, length >>> 0).set(new Uint8Array(answers, 0, length >>> 0));
    },
  },
};

// A trap (the module's panic) leaves its message in the report (exports.rs).
function trapped(error) {
  try {
    return report().error ?? String(error);
  } catch {
    return String(error);
  }
}

function step() {
  if (paused || (maxFrames > 0 && lastFrame >= maxFrames)) return;
  if (denoiseFrom > 0 && lastFrame + 1 === denoiseFrom) denoise = true;
  let failed;
  try {
    failed = exports.strata_web_frame(denoise ? 1 : 0) !== 0;
  } catch (error) {
    postMessage({ kind: 'error', message: trapped(error) });
    return;
  }
  const scores = report();
  if (failed) {
    postMessage({ kind: 'error', message: scores.error });
    return;
  }
  lastFrame = scores.frame;
  const images =
    new Uint8Array(memory(), exports.strata_web_images_ptr() >>> 0, exports.strata_web_images_len() >>> 0).slice();
  postMessage({ kind: 'frame', scores, images }, [images.buffer]);
  queued = true;
  setTimeout(() => {
    queued = false;
    step();
  }, 0);
}

async function start(message) {
  control = new Int32Array(message.control);
  answers = message.answers;
  maxFrames = message.maxFrames;
  denoiseFrom = message.denoiseFrom;
  const module = await WebAssembly.instantiateStreaming(fetch('strata_web.wasm'), imports);
  exports = module.instance.exports;
  const response = await fetch('reference.bin');
  if (!response.ok) throw new Error(`reference.bin: HTTP ${response.status}`);
  const reference = new Uint8Array(await response.arrayBuffer());
  const inbox = exports.strata_web_inbox(reference.length) >>> 0;
  new Uint8Array(memory(), inbox, reference.length).set(reference);
  let failed;
  try {
    failed = exports.strata_web_start(message.width, message.height, message.seed) !== 0;
  } catch (error) {
    postMessage({ kind: 'error', message: trapped(error) });
    return;
  }
  if (failed) {
    postMessage({ kind: 'error', message: report().error });
    return;
  }
  postMessage({ kind: 'started', device: report() });
  step();
}

onmessage = (event) => {
  const message = event.data;
  if (message.kind === 'start') {
    start(message).catch((error) => postMessage({ kind: 'error', message: String(error && error.message || error) }));
  } else if (message.kind === 'denoise') {
    denoise = message.on;
  } else if (message.kind === 'pause') {
    const resume = paused && !message.on;
    paused = message.on;
    // A step still queued (paused and resumed within one frame) carries on by itself.
    if (resume && !queued) step();
  }
};
