// main.js: the live comparison page's own thread. Written for strata (web/page/, MIT OR
// Apache-2.0).
//
// It holds the WebGPU device: the worker (worker.js) runs the renderer and sends each of
// its backend's messages here, where executor.js (the same executor as the `webgpu`
// backend's bridge page) runs it on the device and the answer goes back through shared
// memory. Each frame's images and scores come back from the worker and are drawn here.
//
// Where the device cannot run the ReSTIR kernels (its WebGPU allows fewer storage buffers
// per shader stage than they bind), the module says why and shows the path tracer
// converging instead; the page says so above the image.
//
// For the page's test, `?frames=N&denoise-from=K` stops after N frames, has the worker
// turn the denoiser on from frame K (on that frame exactly, so that a native run can do
// the same; the checkbox follows), and posts what the page showed to the server
// (`post/result`; `post/error` on a failure).
import { frame, run, unframe } from './executor.js';

const METHODS = ['ris', 'restir', 'strata'];
const params = new URLSearchParams(location.search);
const maxFrames = Number(params.get('frames') ?? 0);
const denoiseFrom = Number(params.get('denoise-from') ?? 0);
const testing = maxFrames > 0;

const status = document.getElementById('status');
const checkbox = document.getElementById('denoise');
const pause = document.getElementById('pause');
const ratios = [];
const pathErrors = [];
// When each frame was shown (ms since the page started), for the test's account of time.
const frameTimes = [];
let worker = null;
let failed = false;
let unavailable = null;

function say(text, error = false) {
  status.textContent = text;
  status.classList.toggle('error', error);
}

async function post(name, value) {
  if (testing) await fetch(`post/${name}`, { method: 'POST', body: JSON.stringify(value) });
}

// The first failure is the cause: later ones (a worker told its page is gone) are not shown.
async function fail(message) {
  if (failed) return;
  failed = true;
  say(message, true);
  if (worker) worker.terminate();
  await post('error', { message });
}

// A score as shown: '–' for one that is missing or not a finite number.
function formatted(value, digits = null) {
  if (typeof value !== 'number' || !Number.isFinite(value)) return '–';
  return digits === null ? value.toExponential(3) : value.toFixed(digits);
}

// The strata ÷ restir ratio against frame, raw and (where on) after the denoiser.
function plot() {
  const canvas = document.getElementById('ratio-plot');
  const context = canvas.getContext('2d');
  const [width, height] = [canvas.width, canvas.height];
  context.clearRect(0, 0, width, height);
  let [low, high] = [0.5, 1.5];
  for (const r of ratios) {
    for (const v of [r.raw, r.denoised]) {
      if (typeof v === 'number' && Number.isFinite(v)) [low, high] = [Math.min(low, v), Math.max(high, v)];
    }
  }
  const x = (i) => 30 + (i / Math.max(1, ratios.length - 1)) * (width - 40);
  const y = (v) => height - 10 - ((v - low) / (high - low)) * (height - 20);
  context.strokeStyle = '#999';
  context.setLineDash([4, 4]);
  context.beginPath();
  context.moveTo(30, y(1));
  context.lineTo(width - 10, y(1));
  context.stroke();
  context.setLineDash([]);
  context.fillStyle = '#555';
  context.fillText('1', 10, y(1) + 4);
  for (const [key, colour] of [['raw', '#1f5fbf'], ['denoised', '#c0392b']]) {
    context.strokeStyle = colour;
    context.beginPath();
    let drawing = false;
    ratios.forEach((r, i) => {
      const v = r[key];
      if (typeof v !== 'number' || !Number.isFinite(v)) {
        drawing = false;
        return;
      }
      if (drawing) context.lineTo(x(i), y(v));
      else context.moveTo(x(i), y(v));
      drawing = true;
    });
    context.stroke();
  }
}

// Whether an RGBA8 image has more than one value (a blank or flat image does not).
function varied(pixels) {
  let low = 255;
  let high = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    const value = pixels[i] + pixels[i + 1] + pixels[i + 2];
    low = Math.min(low, value);
    high = Math.max(high, value);
  }
  return high > low;
}

// Runs exchange `id`'s message on the device and hands the worker the answer.
async function answer(message, id, control, answers) {
  let bytes;
  try {
    const reply = await run(unframe(message.buffer));
    bytes = frame(reply.header, reply.parts);
    if (bytes.byteLength > answers.byteLength) answers.grow(bytes.byteLength);
  } catch (error) {
    await fail(`the page could not answer the renderer: ${error.message}`);
    Atomics.store(control, 0, 2);
    Atomics.notify(control, 0);
    return;
  }
  new Uint8Array(answers).set(bytes);
  Atomics.store(control, 1, bytes.byteLength);
  Atomics.store(control, 2, id);
  Atomics.store(control, 0, 1);
  Atomics.notify(control, 0);
}

// The path tracer's frame (the fallback): its image and score.
async function showPathTracer(scores, images, settings) {
  const pixels = new Uint8ClampedArray(images.buffer, 0, settings.width * settings.height * 4);
  const context = document.getElementById('image-path').getContext('2d');
  context.putImageData(new ImageData(pixels, settings.width, settings.height), 0, 0);
  const { samples, relmse } = scores.pathTracer;
  pathErrors.push(relmse);
  document.getElementById('score-path').textContent =
    `${samples} samples per pixel, RelMSE ${formatted(relmse)}`;
  if (testing && scores.frame === maxFrames) {
    await post('result', { mode: 'path-tracer', unavailable, scores, varied: [varied(pixels)], relmse: pathErrors });
  }
}

// The comparison's frame: the three images, their scores, the ratio and its plot.
async function showComparison(scores, images, settings) {
  const size = settings.width * settings.height * 4;
  const shown = [];
  const maps = [];
  METHODS.forEach((name, i) => {
    const pixels = new Uint8ClampedArray(images.buffer, i * size, size);
    const context = document.getElementById(`image-${name}`).getContext('2d');
    context.putImageData(new ImageData(pixels, settings.width, settings.height), 0, 0);
    shown.push(varied(pixels));
    // The error maps follow the three images in the module's buffer.
    const map = new Uint8ClampedArray(images.buffer, (METHODS.length + i) * size, size);
    const mapContext = document.getElementById(`error-${name}`).getContext('2d');
    mapContext.putImageData(new ImageData(map, settings.width, settings.height), 0, 0);
    maps.push(varied(map));
    const m = scores.methods[i];
    const denoised = m.denoisedRelmse !== null
      ? `; denoised ${formatted(m.denoisedRelmse)}, mean ${formatted(m.meanDenoisedRelmse)}` : '';
    document.getElementById(`score-${name}`).textContent =
      `RelMSE ${formatted(m.relmse)}, mean ${formatted(m.meanRelmse)}${denoised}`;
  });
  ratios.push({ raw: scores.strataOverRestir, denoised: scores.denoisedStrataOverRestir });
  const denoisedRatio = scores.denoisedStrataOverRestir;
  document.getElementById('ratio').textContent = formatted(scores.strataOverRestir, 3)
    + (denoisedRatio !== null ? ` (after the denoiser: ${formatted(denoisedRatio, 3)})` : '');
  plot();
  // In the test the worker turns the denoiser on by itself; the checkbox follows.
  if (testing && denoiseFrom > 0 && scores.frame >= denoiseFrom) checkbox.checked = true;
  frameTimes.push(Math.round(performance.now()));
  if (testing && scores.frame === maxFrames) {
    await post('result', {
      mode: 'comparison', scores, varied: shown, mapsVaried: maps, ratios, checkbox: checkbox.checked, frameTimes,
    });
  }
}

async function main() {
  const settings = await (await fetch('page.json')).json();
  document.getElementById('reference').textContent =
    `${settings.referenceSamples} samples per pixel, ${settings.width}×${settings.height}`;
  for (const id of [...METHODS.flatMap((name) => [`image-${name}`, `error-${name}`]), 'image-path']) {
    const canvas = document.getElementById(id);
    canvas.width = settings.width;
    canvas.height = settings.height;
  }
  if (!('gpu' in navigator)) {
    await fail('This browser has no WebGPU (navigator.gpu is missing): open the page in a browser with WebGPU on '
      + '(Chrome or Edge 113+, Safari 26+, Firefox 141+ on Windows).');
    return;
  }
  if (!crossOriginIsolated) {
    await fail('The page is not cross-origin isolated, so its worker cannot wait for the GPU: serve it with '
      + '`cargo xtask web`, which sends the headers that allow it.');
    return;
  }
  const control = new Int32Array(new SharedArrayBuffer(12));
  const answers = new SharedArrayBuffer(1 << 20, { maxByteLength: 1 << 30 });
  worker = new Worker('worker.js', { type: 'module' });
  worker.onerror = (event) =>
    fail(`the worker failed: ${event.message ?? 'it did not load (a browser without module workers?)'}`);
  checkbox.addEventListener('change', () => worker.postMessage({ kind: 'denoise', on: checkbox.checked }));
  pause.addEventListener('click', () => {
    const on = pause.textContent === 'Pause';
    pause.textContent = on ? 'Resume' : 'Pause';
    worker.postMessage({ kind: 'pause', on });
  });
  let device = '';
  worker.onmessage = async (event) => {
    const message = event.data;
    if (failed) return;
    try {
      if (message.kind === 'exchange') {
        await answer(message.message, message.id, control, answers);
      } else if (message.kind === 'started') {
        device = `${message.device.adapter} (${message.device.driver})`;
        unavailable = message.device.unavailable;
        if (unavailable) {
          // The fallback: the path tracer, and why ReSTIR is not shown.
          for (const id of ['methods', 'colour-bar', 'ratio-line', 'ratio-plot']) document.getElementById(id).hidden = true;
          document.getElementById('path-tracer').hidden = false;
          checkbox.disabled = true;
          device += `. ReSTIR cannot run on this device (${message.device.unavailable}); `
            + 'shown instead: the path tracer converging, one sample per pixel a frame';
        }
        say(`Rendering on ${device}`);
      } else if (message.kind === 'error') {
        await fail(message.message);
      } else if (message.kind === 'frame') {
        const { scores, images } = message;
        if (scores.pathTracer) await showPathTracer(scores, images, settings);
        else await showComparison(scores, images, settings);
        say(`Rendering on ${device} · frame ${scores.frame}`);
      }
    } catch (error) {
      await fail(`the page failed to show a frame: ${error.message}`);
    }
  };
  worker.postMessage({
    kind: 'start', control: control.buffer, answers, maxFrames, denoiseFrom,
    width: settings.width, height: settings.height, seed: settings.seed,
  });
}

main().catch((error) => fail(String(error && error.message || error)));
