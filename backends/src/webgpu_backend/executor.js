// strata's WebGPU executor: runs the `webgpu` backend's messages on a GPUDevice it
// holds. Written for strata (backends/src/webgpu_backend/). Two pages import it: the
// bridge's page (page.js), which the backend opens in headless Chromium and feeds over
// loopback HTTP, and the live comparison page (web/page/), whose worker runs the
// renderer compiled to WebAssembly and hands it each message.
//
// Both directions use one framing (framing.rs): a little-endian u32 with the length of a
// JSON header, the header, then raw bytes (buffer and texture contents, WGSL) that the
// header points into as [offset, length] pairs.
//
// A message is {ops: [...]}: operations run in order, each inside error scopes
// (validation, out-of-memory, internal). The answer is {results: [[offset, length], ...]}
// for the operations that return bytes, or {error, kind, op} for the first that failed,
// after which the rest are not run. A lost device fails every later message.

const state = {
  device: null,
  lost: null,
  uncaptured: null,
  buffers: new Map(),
  textures: new Map(),
  samplers: new Map(),
  pipelines: new Map(),
  timestamps: null,
  // Scopes of operations whose errors are not awaited yet: [{what, promises}].
  pending: [],
};

/** An error that carries its kind for the Rust side (`validation`, `lost`, ...). */
function failure(kind, message) {
  const error = new Error(message);
  error.kind = kind;
  return error;
}

/** One line: newlines and runs of blanks become one space. */
function oneLine(text) {
  return String(text).replace(/\s+/g, ' ').trim();
}

/** One framed message: `header` (JSON) and `parts` (Uint8Arrays) after it. */
export function frame(header, parts) {
  const json = new TextEncoder().encode(JSON.stringify(header));
  const total = 4 + json.length + parts.reduce((sum, part) => sum + part.byteLength, 0);
  const bytes = new Uint8Array(total);
  new DataView(bytes.buffer).setUint32(0, json.length, true);
  bytes.set(json, 4);
  let offset = 4 + json.length;
  for (const part of parts) {
    bytes.set(part, offset);
    offset += part.byteLength;
  }
  return bytes;
}

/** A framed message's {header, payload} (an ArrayBuffer in). */
export function unframe(buffer) {
  const view = new DataView(buffer);
  const length = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  return { header, payload: new Uint8Array(buffer, 4 + length) };
}

function slice(payload, [offset, length]) {
  return payload.subarray(offset, offset + length);
}

function device() {
  if (state.lost !== null) throw failure('lost', state.lost);
  if (state.device === null) throw failure('other', 'no device: `init` has not run');
  return state.device;
}

function lookup(map, id, what) {
  const found = map.get(id);
  if (found === undefined) throw failure('other', `unknown ${what} ${id}`);
  return found;
}

function pushScopes(gpu) {
  gpu.pushErrorScope('internal');
  gpu.pushErrorScope('out-of-memory');
  gpu.pushErrorScope('validation');
}

function popScopes(gpu) {
  return [gpu.popErrorScope(), gpu.popErrorScope(), gpu.popErrorScope()];
}

/** Runs a synchronous operation inside error scopes whose result is awaited later. */
function quick(what, operation) {
  const gpu = device();
  pushScopes(gpu);
  let value;
  try {
    value = operation(gpu);
  } finally {
    state.pending.push({ what, promises: popScopes(gpu) });
  }
  return value;
}

/** Awaits the error scopes of every quick operation so far; throws the first error. */
async function settle() {
  const pending = state.pending;
  state.pending = [];
  let first = null;
  for (const { what, promises } of pending) {
    const errors = await Promise.all(promises);
    const error = errors.find((e) => e !== null);
    if (error && first === null) first = scopeFailure(error, what);
  }
  if (first !== null) throw first;
  if (state.uncaptured !== null) {
    const message = state.uncaptured;
    state.uncaptured = null;
    throw failure('validation', `uncaptured: ${message}`);
  }
  if (state.lost !== null) throw failure('lost', state.lost);
}

function scopeFailure(error, what) {
  const kind = error instanceof GPUOutOfMemoryError ? 'out-of-memory'
    : error instanceof GPUInternalError ? 'internal' : 'validation';
  const failed = failure(kind, oneLine(error.message));
  failed.what = what;
  return failed;
}

/** Runs an asynchronous operation inside its own error scopes, awaited at once. */
async function scoped(what, operation) {
  await settle();
  const gpu = device();
  pushScopes(gpu);
  let value;
  let thrown = null;
  try {
    value = await operation(gpu);
  } catch (error) {
    thrown = error;
  }
  const errors = await Promise.all(popScopes(gpu));
  const error = errors.find((e) => e !== null);
  // Tint's own message (with its line) says more than the scope's copy of it.
  if (thrown !== null && thrown.kind === 'shader') throw thrown;
  if (error) throw scopeFailure(error, what);
  if (thrown !== null) throw thrown;
  if (state.lost !== null) throw failure('lost', state.lost);
  return value;
}

async function init(op) {
  if (!('gpu' in navigator)) {
    throw failure('unavailable', 'navigator.gpu is undefined: this browser has no WebGPU here '
      + '(it needs --enable-unsafe-webgpu on Linux and a secure context)');
  }
  const adapter = await navigator.gpu.requestAdapter({ powerPreference: 'high-performance' });
  if (adapter === null) throw failure('no-adapter', 'navigator.gpu.requestAdapter() gave no adapter');
  const wanted = ['timestamp-query', 'shader-f16', 'float32-filterable'];
  if (op.subgroups) wanted.push('subgroups');
  const requiredFeatures = wanted.filter((name) => adapter.features.has(name));
  // Every limit at the adapter's best, as the wgpu backend asks.
  const requiredLimits = {};
  for (const name in adapter.limits) {
    if (typeof adapter.limits[name] === 'number') requiredLimits[name] = adapter.limits[name];
  }
  let gpu;
  try {
    gpu = await adapter.requestDevice({ label: 'strata', requiredFeatures, requiredLimits });
  } catch (error) {
    throw failure('device', oneLine(error.message));
  }
  state.device = gpu;
  gpu.lost.then((info) => {
    state.lost = `${info.reason}: ${oneLine(info.message)}`;
  });
  gpu.addEventListener('uncapturederror', (event) => {
    if (state.uncaptured === null) state.uncaptured = oneLine(event.error.message);
  });
  const limits = {};
  for (const name in gpu.limits) {
    if (typeof gpu.limits[name] === 'number') limits[name] = gpu.limits[name];
  }
  const info = adapter.info;
  const features = [...gpu.features];
  if (features.includes('timestamp-query')) {
    state.timestamps = {
      set: gpu.createQuerySet({ type: 'timestamp', count: 2 }),
      resolve: gpu.createBuffer({ size: 16, usage: GPUBufferUsage.QUERY_RESOLVE | GPUBufferUsage.COPY_SRC }),
    };
  }
  const header = {
    vendor: info.vendor,
    architecture: info.architecture,
    device: info.device,
    description: info.description,
    fallback: Boolean(info.isFallbackAdapter),
    subgroups: features.includes('subgroups') ? [info.subgroupMinSize ?? 0, info.subgroupMaxSize ?? 0] : null,
    features,
    limits,
    userAgent: navigator.userAgent,
  };
  return new TextEncoder().encode(JSON.stringify(header));
}

const BUFFER_USAGE = () => GPUBufferUsage.STORAGE | GPUBufferUsage.UNIFORM
  | GPUBufferUsage.COPY_SRC | GPUBufferUsage.COPY_DST;
const TEXTURE_USAGE = () => GPUTextureUsage.TEXTURE_BINDING | GPUTextureUsage.STORAGE_BINDING
  | GPUTextureUsage.COPY_SRC | GPUTextureUsage.COPY_DST;

/** Copies `size` bytes (a multiple of 4) out of `source` through a mapped staging buffer. */
async function readBack(gpu, what, copy, size) {
  const staging = gpu.createBuffer({ label: what, size, usage: GPUBufferUsage.MAP_READ | GPUBufferUsage.COPY_DST });
  try {
    const encoder = gpu.createCommandEncoder({ label: what });
    copy(encoder, staging);
    gpu.queue.submit([encoder.finish()]);
    await staging.mapAsync(GPUMapMode.READ);
    return new Uint8Array(staging.getMappedRange().slice(0));
  } finally {
    staging.destroy();
  }
}

async function createPipeline(op, payload) {
  const code = new TextDecoder().decode(slice(payload, op.wgsl));
  const what = `pipeline creation for \`${op.label}\``;
  const pipeline = await scoped(what, async (gpu) => {
    const module = gpu.createShaderModule({ label: op.label, code });
    const compilation = await module.getCompilationInfo();
    const errors = compilation.messages.filter((m) => m.type === 'error');
    if (errors.length > 0) {
      const first = errors[0];
      const error = failure('shader', oneLine(first.message));
      error.line = first.lineNum;
      error.column = first.linePos;
      error.count = errors.length;
      throw error;
    }
    const layouts = op.layouts.map((entries) => gpu.createBindGroupLayout({ label: op.label, entries }));
    try {
      const compute = await gpu.createComputePipelineAsync({
        label: op.label,
        layout: gpu.createPipelineLayout({ label: op.label, bindGroupLayouts: layouts }),
        compute: { module, entryPoint: op.entry, constants: op.constants },
      });
      return { compute, layouts };
    } catch (error) {
      throw failure(error.reason === 'internal' ? 'internal' : 'pipeline', oneLine(error.message));
    }
  });
  state.pipelines.set(op.key, pipeline);
}

function bindGroups(gpu, op, pipeline) {
  return pipeline.layouts.map((layout, group) => gpu.createBindGroup({
    label: op.label,
    layout,
    entries: op.binds.filter((bind) => bind.group === group).map((bind) => {
      let resource;
      if ('buffer' in bind) {
        resource = { buffer: lookup(state.buffers, bind.buffer, 'buffer').buffer };
      } else if ('sampler' in bind) {
        resource = lookup(state.samplers, bind.sampler, 'sampler');
      } else {
        const texture = lookup(state.textures, bind.texture, 'texture');
        const view = { dimension: bind.viewDimension };
        if (bind.storage) view.mipLevelCount = 1;
        resource = texture.createView(view);
      }
      return { binding: bind.binding, resource };
    }),
  }));
}

async function dispatch(op) {
  const pipeline = state.pipelines.get(op.key);
  if (pipeline === undefined) throw failure('other', `no pipeline for \`${op.label}\` (its creation failed)`);
  const what = `dispatch of \`${op.label}\``;
  const encode = (gpu) => {
    const groups = bindGroups(gpu, op, pipeline);
    const encoder = gpu.createCommandEncoder({ label: op.label });
    const descriptor = { label: op.label };
    if (op.timed) {
      descriptor.timestampWrites = { querySet: state.timestamps.set, beginningOfPassWriteIndex: 0, endOfPassWriteIndex: 1 };
    }
    const pass = encoder.beginComputePass(descriptor);
    pass.setPipeline(pipeline.compute);
    groups.forEach((group, index) => pass.setBindGroup(index, group));
    pass.dispatchWorkgroups(...op.workgroups);
    pass.end();
    if (op.timed) encoder.resolveQuerySet(state.timestamps.set, 0, 2, state.timestamps.resolve, 0);
    gpu.queue.submit([encoder.finish()]);
  };
  if (!op.timed) {
    quick(what, encode);
    return null;
  }
  if (state.timestamps === null) throw failure('other', 'timestamp queries are not supported');
  await scoped(what, async (gpu) => encode(gpu));
  return scoped(`timing of \`${op.label}\``, (gpu) => readBack(gpu, 'strata timestamps',
    (encoder, staging) => encoder.copyBufferToBuffer(state.timestamps.resolve, 0, staging, 0, 16), 16));
}

async function execute(op, payload) {
  switch (op.op) {
    case 'init':
      return init(op);
    case 'createBuffer':
      quick(`creation of buffer \`${op.label}\` (${op.size} bytes)`, (gpu) => {
        const buffer = gpu.createBuffer({ label: op.label, size: Math.ceil(op.size / 4) * 4, usage: BUFFER_USAGE() });
        state.buffers.set(op.id, { buffer, size: op.size });
      });
      return null;
    case 'writeBuffer': {
      const entry = lookup(state.buffers, op.id, 'buffer');
      quick(`write of buffer ${op.id}`, (gpu) => gpu.queue.writeBuffer(entry.buffer, op.offset, slice(payload, op.data)));
      return null;
    }
    case 'readBuffer': {
      const entry = lookup(state.buffers, op.id, 'buffer');
      const padded = Math.ceil(entry.size / 4) * 4;
      const bytes = await scoped(`read-back of buffer ${op.id}`, (gpu) => readBack(gpu, 'strata read-back',
        (encoder, staging) => encoder.copyBufferToBuffer(entry.buffer, 0, staging, 0, padded), padded));
      return bytes.subarray(0, entry.size);
    }
    case 'destroyBuffer': {
      const entry = state.buffers.get(op.id);
      state.buffers.delete(op.id);
      if (entry) entry.buffer.destroy();
      return null;
    }
    case 'createTexture':
      quick(`creation of texture \`${op.label}\``, (gpu) => {
        state.textures.set(op.id, gpu.createTexture({
          label: op.label,
          dimension: op.dimension,
          size: op.size,
          mipLevelCount: op.mipLevels,
          format: op.format,
          usage: TEXTURE_USAGE(),
        }));
      });
      return null;
    case 'writeTexture': {
      const texture = lookup(state.textures, op.id, 'texture');
      quick(`write of texture ${op.id}`, (gpu) => gpu.queue.writeTexture(
        { texture, mipLevel: op.level },
        slice(payload, op.data),
        { offset: 0, bytesPerRow: op.bytesPerRow, rowsPerImage: op.size[1] },
        op.size,
      ));
      return null;
    }
    case 'readTexture': {
      const texture = lookup(state.textures, op.id, 'texture');
      const [width, height, depth] = op.size;
      const row = op.bytesPerRow;
      const padded = Math.ceil(row / 256) * 256;
      const bytes = await scoped(`read-back of texture ${op.id}`, (gpu) => readBack(gpu, 'strata texture read-back',
        (encoder, staging) => encoder.copyTextureToBuffer(
          { texture, mipLevel: op.level },
          { buffer: staging, bytesPerRow: padded, rowsPerImage: height },
          [width, height, depth],
        ), padded * height * depth));
      const tight = new Uint8Array(row * height * depth);
      for (let r = 0; r < height * depth; r++) tight.set(bytes.subarray(r * padded, r * padded + row), r * row);
      return tight;
    }
    case 'destroyTexture': {
      const texture = state.textures.get(op.id);
      state.textures.delete(op.id);
      if (texture) texture.destroy();
      return null;
    }
    case 'createSampler':
      quick(`creation of sampler ${op.id}`, (gpu) => state.samplers.set(op.id, gpu.createSampler(op.descriptor)));
      return null;
    case 'destroySampler':
      state.samplers.delete(op.id);
      return null;
    case 'pipeline':
      await createPipeline(op, payload);
      return null;
    case 'dispatch':
      return dispatch(op);
    default:
      throw failure('other', `unknown operation \`${op.op}\``);
  }
}

/** Runs one message's operations; its answer as {header, parts} for `frame`. */
export async function run({ header, payload }) {
  const parts = [];
  const results = [];
  let offset = 0;
  for (let index = 0; index < header.ops.length; index++) {
    try {
      const bytes = await execute(header.ops[index], payload);
      if (bytes !== null && bytes !== undefined) {
        parts.push(bytes);
        results.push([offset, bytes.byteLength]);
        offset += bytes.byteLength;
      }
      if (index === header.ops.length - 1) await settle();
    } catch (error) {
      state.pending = [];
      const answer = { error: oneLine(error.message), kind: error.kind ?? 'other', op: index };
      if (error.what) answer.what = error.what;
      if (error.line) Object.assign(answer, { line: error.line, column: error.column, count: error.count });
      return { header: answer, parts: [] };
    }
  }
  return { header: { results }, parts };
}
