// The page of tests/tests/es_module.rs: runs the package's web/strata.js on the cases the
// test serves (cases.json, inputs.bin) and posts every frame's selections and resampling
// results, and the message of every bad input, back to the test (post/result). Written
// for strata (MIT OR Apache-2.0).
import * as strata from './web/strata.js';

const post = (name, body) => fetch(`post/${name}`, { method: 'POST', body });

// One message: a little-endian u32 with the JSON header's length, the header, the bytes.
function frame(header, chunks) {
  const json = new TextEncoder().encode(JSON.stringify(header));
  const total = 4 + json.length + chunks.reduce((n, c) => n + c.byteLength, 0);
  const bytes = new Uint8Array(total);
  new DataView(bytes.buffer).setUint32(0, json.length, true);
  bytes.set(json, 4);
  let at = 4 + json.length;
  for (const chunk of chunks) {
    bytes.set(chunk, at);
    at += chunk.byteLength;
  }
  return bytes;
}

// The package's example page in a frame of this page (same origin), run alongside the
// cases; its log once it says `done` or `error: ...`.
function runExample() {
  const frame = document.createElement('iframe');
  frame.src = 'web/example.html';
  document.body.append(frame);
  return new Promise((resolve) => {
    const started = performance.now();
    const poll = () => {
      const text = frame.contentDocument?.getElementById('log')?.textContent ?? '';
      if (/\n(done|error: .*)$/.test(text) || performance.now() - started > 60000) resolve(text);
      else setTimeout(poll, 100);
    };
    poll();
  });
}

async function main() {
  const example = runExample();
  const cases = await (await fetch('cases.json')).json();
  const inputs = new Uint8Array(await (await fetch('inputs.bin')).arrayBuffer());
  const adapter = navigator.gpu ? await navigator.gpu.requestAdapter() : null;
  if (!adapter) {
    await post('skip', navigator.gpu ? 'no WebGPU adapter' : 'no navigator.gpu');
    return;
  }
  const requiredFeatures = adapter.features.has('subgroups') ? ['subgroups'] : [];
  const device = await adapter.requestDevice({ requiredFeatures });
  const uncaptured = [];
  device.addEventListener('uncapturederror', (event) => uncaptured.push(event.error.message));
  const { width, height, frames, seed } = cases;
  const part = (name) => {
    const [offset, length] = cases.inputs[name];
    return inputs.subarray(offset, offset + length);
  };
  const usage = GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC | GPUBufferUsage.COPY_DST;
  const filled = (bytes) => {
    const buffer = device.createBuffer({ size: Math.max(bytes.byteLength, 4), usage });
    device.queue.writeBuffer(buffer, 0, bytes);
    return buffer;
  };
  const candidates = filled(part('candidates'));
  const payloads = filled(part('payloads'));
  const resampleInputs = filled(part('resample'));
  const chunks = [];
  const runs = [];
  for (const run of cases.runs) {
    if (run.histogram === 'block_histogram_subgroup' && !device.features.has('subgroups')) {
      runs.push({ skipped: 'the device has no subgroups' });
      continue;
    }
    const started = performance.now();
    const pass = await strata.createStrataSelection(device, {
      width,
      height,
      settings: run.settings,
      seed,
      histogram: run.histogram,
    });
    const created = performance.now();
    const selections = device.createBuffer({ size: pass.bufferSize('selections'), usage });
    const resampled = device.createBuffer({ size: pass.bufferSize('resampled'), usage });
    const bindings = pass.bind({
      candidates,
      payloads: run.payloads ? payloads : undefined,
      selections,
      resample: { inputs: resampleInputs, outputs: resampled },
    });
    for (let f = 0; f < frames; f++) {
      const readSelections = device.createBuffer({ size: selections.size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
      const readResampled = device.createBuffer({ size: resampled.size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
      const encoder = device.createCommandEncoder();
      pass.encodeSelection(encoder, bindings, f);
      pass.encodeResampling(encoder, bindings);
      encoder.copyBufferToBuffer(selections, 0, readSelections, 0, selections.size);
      encoder.copyBufferToBuffer(resampled, 0, readResampled, 0, resampled.size);
      device.queue.submit([encoder.finish()]);
      await Promise.all([readSelections.mapAsync(GPUMapMode.READ), readResampled.mapAsync(GPUMapMode.READ)]);
      chunks.push(new Uint8Array(readSelections.getMappedRange().slice(0)));
      chunks.push(new Uint8Array(readResampled.getMappedRange().slice(0)));
      readSelections.destroy();
      readResampled.destroy();
    }
    runs.push({ histogram: pass.histogramKernel, created_ms: created - started, ms: performance.now() - started });
    selections.destroy();
    resampled.destroy();
    pass.destroy();
  }

  // Bad inputs: each must throw a StrataError naming the field.
  const errors = {};
  const attempt = async (name, what) => {
    try {
      await what();
      errors[name] = { thrown: false };
    } catch (error) {
      errors[name] = { thrown: true, type: error.name, field: error.field ?? null, message: error.message };
    }
  };
  const create = (options) => strata.createStrataSelection(device, { width, height, ...options });
  const good = await create({ settings: { blockSize: 8 } });
  const selections = device.createBuffer({ size: good.bufferSize('selections'), usage });
  await attempt('candidates_5', () => create({ settings: { candidates: 5 } }));
  await attempt('block_size_12', () => create({ settings: { blockSize: 12 } }));
  await attempt('sampler_sobol', () => create({ settings: { sampler: 'sobol' } }));
  await attempt('unknown_setting', () => create({ settings: { blocksize: 8 } }));
  await attempt('width_0', () => strata.createStrataSelection(device, { width: 0, height }));
  await attempt('histogram_name', () => create({ histogram: 'bitonic' }));
  await attempt('small_candidates', async () => good.bind({ candidates: device.createBuffer({ size: 8, usage }), selections }));
  await attempt('no_storage', async () =>
    good.bind({ candidates, selections: device.createBuffer({ size: selections.size, usage: GPUBufferUsage.COPY_SRC }) }),
  );
  await attempt('offset', async () => good.bind({ candidates: { buffer: candidates, offset: 4 }, selections }));
  await attempt('overlap', async () => good.bind({ candidates, selections, payloads: { buffer: selections } }));
  await attempt('missing_selections', async () => good.bind({ candidates }));
  await attempt('no_resample', async () => good.encodeResampling(device.createCommandEncoder(), good.bind({ candidates, selections })));
  await attempt('bad_frame', async () =>
    good.encodeSelection(device.createCommandEncoder(), good.bind({ candidates, selections }), -1),
  );
  await attempt('good_bind', async () => good.bind({ candidates, selections }));
  // The pass's image size and settings are fixed (its buffers were sized for them): a
  // module's code is strict, so writing them throws.
  await attempt('set_width', async () => {
    good.width = 16;
  });
  await attempt('set_height', async () => {
    good.height = 16;
  });
  await attempt('set_settings', async () => {
    good.settings = { blockSize: 4 };
  });
  await attempt('set_setting', async () => {
    good.settings.blockSize = 4;
  });
  await attempt('set_kernel', async () => {
    good.histogramKernel = 'block_histogram';
  });
  await attempt('set_groups', async () => {
    good.bind({ candidates, selections }).groups[0] = null;
  });
  // Two roles in one buffer at disjoint, aligned offsets: each is bound with the bytes it
  // needs, so they neither overlap nor exceed the buffer.
  const step = device.limits.minStorageBufferOffsetAlignment;
  const second = Math.ceil(good.bufferSize('candidates') / step) * step;
  const shared = device.createBuffer({ size: second + good.bufferSize('selections'), usage });
  await attempt('shared_buffer', async () =>
    good.bind({ candidates: { buffer: shared }, selections: { buffer: shared, offset: second } }),
  );
  await device.queue.onSubmittedWorkDone();
  const header = {
    example: await example,
    runs,
    errors,
    uncaptured,
    features: [...device.features],
    adapter: adapter.info ? `${adapter.info.vendor} ${adapter.info.architecture} ${adapter.info.description}` : '',
  };
  await post('result', frame(header, chunks));
}

main().catch((error) => post('error', `${error.name}: ${error.message}\n${error.stack}`));
