// example.js: the script of example.html (strata @STRATA_VERSION@): strata.js on
// generated candidates, four frames with resampling, the selections read back and shown.
// Written for the strata project (MIT OR Apache-2.0).
import { createStrataSelection, RECORDS, CONSTANTS, VERSION } from './strata.js';

const log = document.getElementById('log');
const say = (line) => { log.textContent += `\n${line}`; console.log(line); };
log.textContent = `strata.js ${VERSION}`;

const [width, height, frames] = [256, 128, 4];
const pixels = width * height;

// One candidate per pixel: the object its primary ray hits (three discs, the background
// is object 0) and the luminance of its sample (a smooth gradient times a hash, as noisy
// one-sample estimates are).
function candidates() {
  const record = RECORDS.Candidate;
  const bytes = new ArrayBuffer(pixels * record.size);
  const view = new DataView(bytes);
  const discs = [[64, 64, 40], [150, 50, 30], [200, 96, 24]];
  for (let p = 0; p < pixels; p++) {
    const [x, y] = [p % width, Math.floor(p / width)];
    const disc = discs.findIndex(([cx, cy, r]) => (x - cx) ** 2 + (y - cy) ** 2 < r * r);
    const object = disc + 1;
    const hash = (Math.imul(p ^ 0x9e3779b9, 0x85ebca6b) >>> 8) / (1 << 24);
    const key = (0.2 + 0.8 * (x / width)) * (object === 0 ? 0.3 : 1 + object) * hash;
    view.setFloat32(p * record.size + record.fields.key.offset, key, true);
    view.setUint32(p * record.size + record.fields.object_id.offset, object, true);
  }
  return bytes;
}

// Resampling weights: a canonical sample and K selected samples of made-up weights.
function resampleInputs() {
  const record = RECORDS.ResampleInput;
  const bytes = new ArrayBuffer(pixels * record.size);
  const view = new DataView(bytes);
  for (let p = 0; p < pixels; p++) {
    const base = p * record.size;
    for (let i = 0; i < 4; i++) {
      view.setFloat32(base + record.fields.weights.offset + 4 * i, 1 + ((p + i) % 3), true);
      view.setFloat32(base + record.fields.targets.offset + 4 * i, 1 + i, true);
    }
    view.setFloat32(base + record.fields.canonical_weight.offset, 1, true);
    view.setFloat32(base + record.fields.canonical_target.offset, 1, true);
    view.setUint32(base + record.fields.canonical_payload.offset, p, true);
  }
  return bytes;
}

async function main() {
  if (!navigator.gpu) throw new Error('this browser has no WebGPU (navigator.gpu)');
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) throw new Error('no WebGPU adapter');
  const device = await adapter.requestDevice();
  const storage = GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_DST | GPUBufferUsage.COPY_SRC;
  const filled = (bytes) => {
    const buffer = device.createBuffer({ size: bytes.byteLength, usage: storage });
    device.queue.writeBuffer(buffer, 0, bytes);
    return buffer;
  };
  const pass = await createStrataSelection(device, { width, height, settings: { blockSize: 16, candidates: 4 } });
  const selections = device.createBuffer({ size: pass.bufferSize('selections'), usage: storage });
  const resampled = device.createBuffer({ size: pass.bufferSize('resampled'), usage: storage });
  const bindings = pass.bind({
    candidates: filled(candidates()),
    selections,
    resample: { inputs: filled(resampleInputs()), outputs: resampled },
  });
  const readBack = device.createBuffer({ size: selections.size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
  const started = performance.now();
  for (let frame = 0; frame < frames; frame++) {
    const encoder = device.createCommandEncoder();
    pass.encodeSelection(encoder, bindings, frame);
    // An engine would read `selections` here and write `resample_inputs` for this frame.
    pass.encodeResampling(encoder, bindings);
    if (frame === frames - 1) encoder.copyBufferToBuffer(selections, 0, readBack, 0, selections.size);
    device.queue.submit([encoder.finish()]);
  }
  await readBack.mapAsync(GPUMapMode.READ);
  say(`${frames} frames of ${width}x${height} in ${(performance.now() - started).toFixed(1)} ms (with the read-back)`);
  const words = new Uint32Array(readBack.getMappedRange().slice(0));
  readBack.unmap();
  const record = RECORDS.SelectedCandidates;
  const stride = record.size / 4;
  const first = record.fields.payloads.offset / 4;
  const selected = record.fields.selected.offset / 4;
  const image = new ImageData(width, height);
  let withSelection = 0;
  let distance = 0;
  for (let p = 0; p < pixels; p++) {
    const payload = words[p * stride + first];
    let shade = 0;
    if (words[p * stride + selected] > 0 && payload !== CONSTANTS.NO_PAYLOAD) {
      const d = Math.hypot((payload % width) - (p % width), Math.floor(payload / width) - Math.floor(p / width));
      withSelection += 1;
      distance += d;
      shade = Math.min(255, d * 16);
    }
    image.data.set([shade, shade, 255 - shade, 255], p * 4);
  }
  document.getElementById('view').getContext('2d').putImageData(image, 0, 0);
  say(`pixels with a selection: ${withSelection} of ${pixels}`);
  say(`mean distance to the first selected candidate: ${(distance / Math.max(withSelection, 1)).toFixed(2)} pixels`);
  pass.destroy();
  say('done');
}

main().catch((error) => say(`error: ${error.message}`));
