// main.js: the live comparison page's own thread. Written for strata (web/page/, MIT OR
// Apache-2.0).
//
// It holds the WebGPU device: the worker (worker.js) runs the renderer and sends each of
// its backend's messages here, where executor.js (the same executor as the `webgpu`
// backend's bridge page) runs it on the device and the answer goes back through shared
// memory. Each frame's images and scores come back from the worker and are drawn here.
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
let worker = null;

function say(text, error = false) {
  status.textContent = text;
  status.classList.toggle('error', error);
}

async function post(name, value) {
  if (testing) await fetch(`post/${name}`, { method: 'POST', body: JSON.stringify(value) });
}

async function fail(message) {
  say(message, true);
  if (worker) worker.terminate();
  await post('error', { message });
}

function formatted(value) {
  return value === null || value === undefined ? '–' : value.toExponential(3);
}

// The strata ÷ restir ratio against frame, raw and (where on) after the denoiser.
function plot() {
  const canvas = document.getElementById('ratio-plot');
  const context = canvas.getContext('2d');
  const [width, height] = [canvas.width, canvas.height];
  context.clearRect(0, 0, width, height);
  const values = ratios.flatMap((r) => [r.raw, r.denoised]).filter((v) => v !== null && Number.isFinite(v));
  if (values.length === 0) return;
  const low = Math.min(0.5, ...values);
  const high = Math.max(1.5, ...values);
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
      if (v === null || !Number.isFinite(v)) {
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

async function answer(message, control, answers) {
  let bytes;
  try {
    const reply = await run(unframe(message.buffer));
    bytes = frame(reply.header, reply.parts);
    if (bytes.byteLength > answers.byteLength) answers.grow(bytes.byteLength);
  } catch (error) {
    Atomics.store(control, 0, 2);
    Atomics.notify(control, 0);
    await fail(`the page could not answer the renderer: ${error.message}`);
    return;
  }
  new Uint8Array(answers).set(bytes);
  Atomics.store(control, 1, bytes.byteLength);
  Atomics.store(control, 0, 1);
  Atomics.notify(control, 0);
}

async function main() {
  const settings = await (await fetch('page.json')).json();
  document.getElementById('reference').textContent =
    `${settings.referenceSamples} samples per pixel, ${settings.width}×${settings.height}`;
  for (const name of METHODS) {
    const canvas = document.getElementById(`image-${name}`);
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
  const control = new Int32Array(new SharedArrayBuffer(8));
  const answers = new SharedArrayBuffer(1 << 20, { maxByteLength: 1 << 30 });
  worker = new Worker('worker.js', { type: 'module' });
  worker.onerror = (event) => fail(`the worker failed: ${event.message}`);
  checkbox.addEventListener('change', () => worker.postMessage({ kind: 'denoise', on: checkbox.checked }));
  pause.addEventListener('click', () => {
    const on = pause.textContent === 'Pause';
    pause.textContent = on ? 'Resume' : 'Pause';
    worker.postMessage({ kind: 'pause', on });
  });
  worker.onmessage = async (event) => {
    const message = event.data;
    if (message.kind === 'exchange') {
      await answer(message.message, control, answers);
    } else if (message.kind === 'started') {
      say(`Rendering on ${message.device.adapter} (${message.device.driver})`);
    } else if (message.kind === 'error') {
      await fail(message.message);
    } else if (message.kind === 'frame') {
      const { scores, images } = message;
      const size = settings.width * settings.height * 4;
      const shown = [];
      METHODS.forEach((name, i) => {
        const pixels = new Uint8ClampedArray(images.buffer, i * size, size);
        const context = document.getElementById(`image-${name}`).getContext('2d');
        context.putImageData(new ImageData(pixels, settings.width, settings.height), 0, 0);
        shown.push(varied(pixels));
        const m = scores.methods[i];
        const denoised = m.denoisedRelmse !== null
          ? `; denoised ${formatted(m.denoisedRelmse)}, mean ${formatted(m.meanDenoisedRelmse)}` : '';
        document.getElementById(`score-${name}`).textContent =
          `RelMSE ${formatted(m.relmse)}, mean ${formatted(m.meanRelmse)}${denoised}`;
      });
      ratios.push({ raw: scores.strataOverRestir, denoised: scores.denoisedStrataOverRestir });
      const denoisedRatio = scores.denoisedStrataOverRestir;
      document.getElementById('ratio').textContent = scores.strataOverRestir.toFixed(3)
        + (denoisedRatio !== null ? ` (after the denoiser: ${denoisedRatio.toFixed(3)})` : '');
      plot();
      say(`${status.textContent.split(' · ')[0]} · frame ${scores.frame}`);
      if (scores.methods[0].denoisedRelmse !== null) checkbox.checked = true;
      if (testing && scores.frame === maxFrames) {
        await post('result', { scores, varied: shown, ratios, checkbox: checkbox.checked });
      }
    }
  };
  worker.postMessage({
    kind: 'start', control: control.buffer, answers, maxFrames, denoiseFrom,
    width: settings.width, height: settings.height, seed: settings.seed,
  });
}

main().catch((error) => fail(String(error && error.message || error)));
