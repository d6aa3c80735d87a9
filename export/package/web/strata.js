// strata.js: strata's stratified selection pass (Salaün, Balint, Belcour, Heitz, Singh,
// Myszkowski: "Histogram Stratification for Spatio-Temporal Reservoir Sampling",
// SIGGRAPH 2025, §4) on a WebGPU device, as an ES module.
//
// strata @STRATA_VERSION@. Written by `cargo xtask export`: PACKAGE below (every kernel's
// WGSL, binding number, workgroup size, buffer size rule, struct layout and constant) is
// generated from the package's manifest.json; the code around it is written by hand for
// the strata project (MIT OR Apache-2.0). It computes each frame's uniforms and dispatch
// sizes exactly as strata-embed does (a test of the strata repository runs both on the
// same inputs in headless Chromium and compares the bytes).
//
// Use (see strata.d.ts and example.html):
//   const pass = await createStrataSelection(device, { width, height, settings });
//   const bindings = pass.bind({ candidates, selections, resample: { inputs, outputs } });
//   per frame: pass.encodeSelection(encoder, bindings, frame);
//              ... your shaders read `selections` and write `resample_inputs` ...
//              pass.encodeResampling(encoder, bindings);
// Every refusal is a thrown StrataError whose message names the field and its value.

const PACKAGE = /* @STRATA_PACKAGE@ */ null;

/** The strata version that wrote this module. */
export const VERSION = PACKAGE.version;

/** The constants the kernels and the host share (manifest.json `constants`). */
export const CONSTANTS = Object.freeze({ ...PACKAGE.constants });

/** The sampler variants' names, as `settings.sampler` takes them. */
export const SAMPLERS = Object.freeze(PACKAGE.samplers.map((s) => s.name));

/** The block sizes `settings.blockSize` may be. */
export const BLOCK_SIZES = Object.freeze([...PACKAGE.block_sizes]);

/** The histogram kernels (all three give the same output). */
export const HISTOGRAM_KERNELS = Object.freeze(
  PACKAGE.kernels.filter((k) => k.stage === 'histogram').map((k) => k.name),
);

/** The records of the engine's buffers: size and each field's byte offset and WGSL type. */
export const RECORDS = Object.freeze(
  Object.fromEntries(
    PACKAGE.structs.map((s) => [
      s.name,
      Object.freeze({
        size: s.size,
        fields: Object.freeze(
          Object.fromEntries(s.fields.map((f) => [f.name, Object.freeze({ offset: f.offset, type: f.wgsl_type })])),
        ),
      }),
    ]),
  ),
);

/** The paper's settings (strata's `SelectionSettings::default()`). */
export const DEFAULT_SETTINGS = Object.freeze({
  blockSize: PACKAGE.defaults.block_size,
  candidates: PACKAGE.defaults.candidates,
  sampler: PACKAGE.defaults.sampler,
  masking: PACKAGE.defaults.masking,
  blockShift: PACKAGE.defaults.block_shift,
});

/** What the module refuses: `field` names what is wrong (`settings.blockSize`, `buffers.candidates`). */
export class StrataError extends Error {
  constructor(field, message) {
    super(message);
    this.name = 'StrataError';
    this.field = field;
  }
}

const U32_MAX = 0xffffffff;

function show(value) {
  if (typeof value === 'string') return JSON.stringify(value);
  if (typeof value === 'bigint') return `${value}n`;
  if (value === null || value === undefined) return String(value);
  if (typeof value === 'object') return value.constructor?.name ?? 'an object';
  return String(value);
}

function isU32(value) {
  return Number.isInteger(value) && value >= 0 && value <= U32_MAX;
}

function inWords(items) {
  const shown = items.map((i) => (typeof i === 'string' ? JSON.stringify(i) : String(i)));
  return shown.length < 2 ? shown.join('') : `${shown.slice(0, -1).join(', ')} or ${shown[shown.length - 1]}`;
}

const kernelByName = new Map(PACKAGE.kernels.map((k) => [k.name, k]));
const bufferByName = new Map(PACKAGE.buffers.map((b) => [b.name, b]));
const structByName = new Map(PACKAGE.structs.map((s) => [s.name, s]));
const samplerByName = new Map(PACKAGE.samplers.map((s) => [s.name, s.id]));

// The buffers bound as uniforms, and each stage's uniform: its buffer and struct.
const UNIFORM_BUFFERS = new Set(
  PACKAGE.kernels.flatMap((k) => k.bindings.filter((b) => b.descriptor_type === 'uniform_buffer').map((b) => b.buffer)),
);
function uniformOf(stage) {
  const kernel = kernelOfStage(stage);
  const binding = kernel.bindings.find((b) => b.descriptor_type === 'uniform_buffer');
  return { buffer: binding.buffer, struct: kernel.uniform };
}

function kernelOfStage(stage) {
  const kernel = PACKAGE.kernels.find((k) => k.stage === stage);
  if (!kernel) throw new Error(`strata.js: the package has no ${stage} kernel`);
  return kernel;
}

// The settings' JavaScript names and strata's.
const SETTING_NAMES = [
  ['blockSize', 'block_size'],
  ['candidates', 'candidates'],
  ['sampler', 'sampler'],
  ['masking', 'masking'],
  ['blockShift', 'block_shift'],
];

/**
 * Checks `settings` (missing fields take DEFAULT_SETTINGS'); returns them whole, or throws
 * a StrataError naming the field, its value and what it may be.
 */
export function checkSettings(settings = {}) {
  if (settings === null || typeof settings !== 'object' || Array.isArray(settings)) {
    throw new StrataError('settings', `settings = ${show(settings)}: must be an object`);
  }
  const known = SETTING_NAMES.map(([js]) => js);
  for (const key of Object.keys(settings)) {
    if (!known.includes(key)) {
      throw new StrataError(`settings.${key}`, `settings.${key}: not a setting (the settings are ${inWords(known)})`);
    }
  }
  const whole = { ...DEFAULT_SETTINGS, ...settings };
  const bad = (field, expected) => {
    throw new StrataError(`settings.${field}`, `settings.${field} = ${show(whole[field])}: must be ${expected}`);
  };
  if (!BLOCK_SIZES.includes(whole.blockSize)) bad('blockSize', inWords(BLOCK_SIZES));
  const most = CONSTANTS.MAX_SELECTED;
  if (!Number.isInteger(whole.candidates) || whole.candidates < 1 || whole.candidates > most) {
    bad('candidates', `an integer from 1 to ${most}`);
  }
  if (!samplerByName.has(whole.sampler)) bad('sampler', `one of ${inWords(SAMPLERS)}`);
  if (typeof whole.masking !== 'boolean') bad('masking', 'true or false');
  if (typeof whole.blockShift !== 'boolean') bad('blockShift', 'true or false');
  return Object.freeze(whole);
}

function checkImage(width, height) {
  for (const [field, value] of [
    ['width', width],
    ['height', height],
  ]) {
    if (!Number.isInteger(value) || value < 1 || value > U32_MAX) {
      throw new StrataError(field, `${field} = ${show(value)}: must be an integer from 1 to ${U32_MAX}`);
    }
  }
  if (width * height > U32_MAX) {
    throw new StrataError('width', `image size ${width}x${height}: more than 2^32 - 1 pixels`);
  }
}

function checkU32(field, value) {
  if (!isU32(value)) {
    throw new StrataError(field, `${field} = ${show(value)}: must be an integer from 0 to ${U32_MAX}`);
  }
}

// PCG hash of Jarzynski and Olano 2020 (the kernels' `selection_hash`).
function selectionHash(v) {
  const state = (Math.imul(v >>> 0, 747796405) + 2891336453) >>> 0;
  const word = Math.imul(((state >>> ((state >>> 28) + 4)) ^ state) >>> 0, 277803737) >>> 0;
  return ((word >>> 22) ^ word) >>> 0;
}

const ceilDiv = (a, b) => Math.floor((a + b - 1) / b);

/** The block-grid shift [sx, sy] of frame `frame` of the render `seed` (0, 0 without block shifting). */
export function gridShift(settings, frame, seed) {
  const s = checkSettings(settings);
  checkU32('frame', frame);
  checkU32('seed', seed);
  if (!s.blockShift) return [0, 0];
  const h = selectionHash((frame ^ selectionHash((seed ^ 0xb10c) >>> 0)) >>> 0);
  return [h % s.blockSize, (h >>> 16) % s.blockSize];
}

/** Blocks of the largest grid any frame has (what `block_stats` holds). */
export function maxBlocks(settings, width, height) {
  const s = checkSettings(settings);
  checkImage(width, height);
  const b = s.blockSize;
  const extra = s.blockShift ? b - 1 : 0;
  return ceilDiv(width + extra, b) * ceilDiv(height + extra, b);
}

/**
 * Everything frame `frame` of the render `seed` needs: both uniforms (by field) and the
 * workgroups of the histogram and per-pixel dispatches. `maxWorkgroups`: the device's
 * maxComputeWorkgroupsPerDimension.
 */
export function frameParams(settings, width, height, { frame, seed, identityPayload, maxWorkgroups }) {
  const s = checkSettings(settings);
  checkImage(width, height);
  checkU32('frame', frame);
  checkU32('seed', seed);
  checkU32('maxWorkgroups', maxWorkgroups);
  const b = s.blockSize;
  const [shiftX, shiftY] = gridShift(s, frame, seed);
  const blocksX = ceilDiv(width + shiftX, b);
  const blocksY = ceilDiv(height + shiftY, b);
  const blocksPerWorkgroup = Math.floor(CONSTANTS.HISTOGRAM_SLOTS_PER_WORKGROUP / (b * b));
  const total = ceilDiv(blocksX * blocksY, blocksPerWorkgroup);
  const x = Math.min(total, Math.max(maxWorkgroups, 1));
  const [sx, sy] = kernelOfStage('select').workgroup_size;
  return {
    histogram: {
      width,
      height,
      block_size: b,
      log2_block_size: 31 - Math.clz32(b),
      blocks_x: blocksX,
      blocks_y: blocksY,
      workgroups_x: x,
      shift_x: shiftX,
      shift_y: shiftY,
      masking: s.masking ? 1 : 0,
    },
    selection: {
      width,
      height,
      frame,
      seed,
      candidates: s.candidates,
      sampler: samplerByName.get(s.sampler),
      identity_payload: identityPayload ? 1 : 0,
    },
    histogramWorkgroups: [x, ceilDiv(total, x), 1],
    pixelWorkgroups: [ceilDiv(width, sx), ceilDiv(height, sy), 1],
  };
}

// A uniform's bytes: each field of `values` at its offset in the struct's layout; every
// field but the padding (`_`) must be given, and nothing else.
function pack(structName, values) {
  const layout = structByName.get(structName);
  if (!layout) throw new Error(`strata.js: the package declares no struct ${structName}`);
  const bytes = new ArrayBuffer(layout.size);
  const view = new DataView(bytes);
  const given = new Set(Object.keys(values));
  for (const field of layout.fields) {
    if (field.name.startsWith('_')) continue;
    if (!given.delete(field.name)) throw new Error(`strata.js: ${structName}.${field.name} is not computed`);
    if (field.wgsl_type !== 'u32') throw new Error(`strata.js: ${structName}.${field.name} is not a u32`);
    view.setUint32(field.offset, values[field.name], true);
  }
  if (given.size > 0) throw new Error(`strata.js: ${structName} has no field ${[...given].join(', ')}`);
  return bytes;
}

// A buffer's bytes by its size rule.
function ruleBytes(name, pixels, blocks) {
  const { rule, bytes } = bufferByName.get(name).size;
  if (rule === 'fixed') return bytes;
  if (rule === 'per_pixel') return bytes * pixels;
  if (rule === 'per_block') return bytes * blocks;
  throw new Error(`strata.js: buffer ${name} has an unknown size rule ${rule}`);
}

function needLimit(device, limit, needed, why) {
  const available = device.limits[limit];
  if (available < needed) {
    throw new StrataError(
      `device.limits.${limit}`,
      `device limit ${limit} is ${available}, but the stratified selection needs ${needed} (${why})`,
    );
  }
}

// The histogram kernel `choice` names, or for "auto" the package's rule without a device
// type (WebGPU does not tell a CPU adapter apart): the kernel that needs subgroups where
// the device has them, else the rule's last (unconditional) kernel. On a CPU adapter,
// `block_histogram_rank` is faster at every block size: pass it. All give the same output.
function histogramKernel(device, choice) {
  const subgroups = device.features.has('subgroups');
  if (choice === undefined || choice === 'auto') {
    const needing = PACKAGE.kernels.find((k) => k.stage === 'histogram' && k.required_features.includes('subgroups'));
    return subgroups && needing ? needing : kernelByName.get(PACKAGE.histogram_default);
  }
  const kernel = kernelByName.get(choice);
  if (!kernel || kernel.stage !== 'histogram') {
    throw new StrataError(
      'options.histogram',
      `options.histogram = ${show(choice)}: must be "auto" or ${inWords(HISTOGRAM_KERNELS)}`,
    );
  }
  if (kernel.required_features.includes('subgroups') && !subgroups) {
    throw new StrataError(
      'options.histogram',
      `options.histogram = ${show(choice)}: needs the device feature "subgroups", which this device was created without`,
    );
  }
  return kernel;
}

function layoutEntries(kernel) {
  return kernel.bindings.map((b) => ({
    binding: b.binding,
    visibility: GPUShaderStage.COMPUTE,
    buffer: {
      type: b.descriptor_type === 'uniform_buffer' ? 'uniform' : b.access === 'read' ? 'read-only-storage' : 'storage',
    },
  }));
}

async function blueNoiseBytes(given) {
  let bytes = given;
  if (bytes === undefined) {
    const url = new URL(`../${PACKAGE.blue_noise.file}`, import.meta.url);
    const response = await fetch(url);
    if (!response.ok) {
      throw new StrataError('options.blueNoise', `options.blueNoise not given, and ${url} answers ${response.status}`);
    }
    bytes = await response.arrayBuffer();
  }
  if (ArrayBuffer.isView(bytes)) bytes = new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  else if (bytes instanceof ArrayBuffer) bytes = new Uint8Array(bytes);
  else {
    throw new StrataError('options.blueNoise', `options.blueNoise = ${show(given)}: must be an ArrayBuffer or a typed array`);
  }
  if (bytes.byteLength !== PACKAGE.blue_noise.bytes) {
    throw new StrataError(
      'options.blueNoise',
      `options.blueNoise has ${bytes.byteLength} bytes, but the blue-noise tables (${PACKAGE.blue_noise.file}) have ${PACKAGE.blue_noise.bytes}`,
    );
  }
  return bytes;
}

// Each device's pipelines by kernel name, made once and shared by every pass on the
// device (a pass per image size or setting costs its buffers only).
const pipelineCache = new WeakMap();

// The kernel's bind-group layout and compute pipeline on `device`.
function pipelineOf(device, kernel) {
  let pipelines = pipelineCache.get(device);
  if (!pipelines) {
    pipelines = new Map();
    pipelineCache.set(device, pipelines);
  }
  let made = pipelines.get(kernel.name);
  if (!made) {
    made = makePipeline(device, kernel);
    pipelines.set(kernel.name, made);
    made.catch(() => pipelines.delete(kernel.name));
  }
  return made;
}

async function makePipeline(device, kernel) {
  const label = `strata ${kernel.name}`;
  device.pushErrorScope('validation');
  const layout = device.createBindGroupLayout({ label, entries: layoutEntries(kernel) });
  const module = device.createShaderModule({ label, code: kernel.wgsl });
  const failed = await device.popErrorScope();
  if (failed) {
    throw new StrataError('device', `WebGPU error while creating the \`${kernel.name}\` shader: ${failed.message}`);
  }
  try {
    const pipeline = await device.createComputePipelineAsync({
      label,
      layout: device.createPipelineLayout({ label, bindGroupLayouts: [layout] }),
      compute: { module, entryPoint: kernel.entry_point },
    });
    return { kernel, layout, pipeline };
  } catch (error) {
    throw new StrataError('device', `WebGPU error while creating the \`${kernel.name}\` pipeline: ${error.message}`);
  }
}

const OPTION_NAMES = ['width', 'height', 'settings', 'seed', 'histogram', 'blueNoise', 'label'];

/**
 * Makes the pass on `device` for a `width` x `height` image: the pipelines (from the
 * package's WGSL), the pass's own buffers (sorted lists, cluster spans, block counters,
 * the blue-noise tables: about 1.3 MiB + 16 bytes per pixel) and its uniforms. Throws a
 * StrataError for a bad option or setting or a device limit below what the pass needs.
 */
export async function createStrataSelection(device, options) {
  if (typeof GPUDevice === 'undefined' || !(device instanceof GPUDevice)) {
    throw new StrataError('device', `device = ${show(device)}: must be a GPUDevice`);
  }
  if (options === null || typeof options !== 'object') {
    throw new StrataError('options', `options = ${show(options)}: must be { width, height, settings }`);
  }
  for (const key of Object.keys(options)) {
    if (!OPTION_NAMES.includes(key)) {
      throw new StrataError(`options.${key}`, `options.${key}: not an option (the options are ${inWords(OPTION_NAMES)})`);
    }
  }
  const { width, height, seed = 0 } = options;
  checkImage(width, height);
  const settings = checkSettings(options.settings);
  checkU32('seed', seed);
  const histogram = histogramKernel(device, options.histogram);
  const kernels = [histogram, kernelOfStage('select'), kernelOfStage('resample')];
  for (const kernel of kernels) {
    const name = kernel.entry_point;
    const storage = kernel.bindings.filter((b) => b.descriptor_type !== 'uniform_buffer').length;
    needLimit(device, 'maxStorageBuffersPerShaderStage', storage, `\`${name}\` binds ${storage} storage buffers`);
    needLimit(device, 'maxComputeWorkgroupStorageSize', kernel.workgroup_memory_bytes, `\`${name}\`'s workgroup memory`);
    const [x, y, z] = kernel.workgroup_size;
    needLimit(device, 'maxComputeInvocationsPerWorkgroup', x * y * z, `\`${name}\` has @workgroup_size(${x}, ${y}, ${z})`);
    needLimit(device, 'maxComputeWorkgroupSizeX', x, `\`${name}\``);
    needLimit(device, 'maxComputeWorkgroupSizeY', y, `\`${name}\``);
  }
  const [sx, sy] = kernelOfStage('select').workgroup_size;
  const widest = Math.max(ceilDiv(width, sx), ceilDiv(height, sy));
  needLimit(device, 'maxComputeWorkgroupsPerDimension', widest, `a ${width}x${height} image in ${sx}x${sy}-pixel workgroups`);
  const pixels = width * height;
  const blocks = maxBlocks(settings, width, height);
  const largest = PACKAGE.buffers
    .filter((b) => b.size.rule !== 'fixed')
    .map((b) => [ruleBytes(b.name, pixels, blocks), b.name])
    .reduce((a, b) => (b[0] > a[0] ? b : a));
  needLimit(device, 'maxStorageBufferBindingSize', largest[0], `buffer \`${largest[1]}\` of a ${width}x${height} image`);
  needLimit(device, 'maxBufferSize', largest[0], `buffer \`${largest[1]}\` of a ${width}x${height} image`);
  const noise = await blueNoiseBytes(options.blueNoise);
  const label = typeof options.label === 'string' ? options.label : 'strata';

  device.pushErrorScope('out-of-memory');
  device.pushErrorScope('validation');
  const own = {};
  for (const buffer of PACKAGE.buffers.filter((b) => b.owner === 'pass')) {
    const uniform = UNIFORM_BUFFERS.has(buffer.name);
    const usage = uniform
      ? GPUBufferUsage.UNIFORM | GPUBufferUsage.COPY_DST
      : GPUBufferUsage.STORAGE | GPUBufferUsage.COPY_SRC | GPUBufferUsage.COPY_DST;
    const size = Math.max(4, ruleBytes(buffer.name, pixels, blocks));
    own[buffer.name] = device.createBuffer({ label: `${label} ${buffer.name}`, size, usage });
  }
  // Bound as `payloads` when the engine has none (never read then).
  own.unused_payloads = device.createBuffer({ label: `${label} unused payloads`, size: 4, usage: GPUBufferUsage.STORAGE });
  device.queue.writeBuffer(own.blue_noise, 0, noise);
  // Both scopes popped at once, so that no other scope pushed meanwhile on this device
  // (another pass being made, the engine's own) is popped in their place.
  const [validation, memory] = await Promise.all([device.popErrorScope(), device.popErrorScope()]);
  const failed = validation ?? memory;
  if (failed) {
    Object.values(own).forEach((b) => b.destroy());
    throw new StrataError('device', `WebGPU error while creating the pass's buffers: ${failed.message}`);
  }
  let pipelines;
  try {
    pipelines = await Promise.all(kernels.map((kernel) => pipelineOf(device, kernel)));
  } catch (error) {
    Object.values(own).forEach((b) => b.destroy());
    throw error;
  }
  return new StrataSelection(device, { width, height, settings, seed, own, pipelines, label });
}

const ENGINE_ROLES = PACKAGE.buffers.filter((b) => b.owner === 'engine').map((b) => b.name);

/** Bind groups of one set of engine buffers, made by StrataSelection.bind. */
export class StrataBindings {
  #pass;
  constructor(pass, groups, identityPayload, resample) {
    this.#pass = pass;
    this.groups = Object.freeze(groups);
    this.identityPayload = identityPayload;
    this.resample = resample;
    Object.freeze(this);
  }
  /** Whether these bindings were made by `pass`'s bind(). */
  belongsTo(pass) {
    return this.#pass === pass;
  }
}

/** The pass on one device, image size and settings (made by createStrataSelection). */
export class StrataSelection {
  #device;
  #own;
  #pipelines;
  #label;
  #seed;
  #width;
  #height;
  #settings;
  constructor(device, { width, height, settings, seed, own, pipelines, label }) {
    this.#device = device;
    this.#width = width;
    this.#height = height;
    // Frozen by checkSettings: the pass's buffers and grid were sized for these settings.
    this.#settings = settings;
    this.#seed = seed;
    this.#own = own;
    this.#pipelines = pipelines;
    this.#label = label;
  }

  /** The image's width (fixed: the pass's buffers are sized for it). */
  get width() {
    return this.#width;
  }

  /** The image's height. */
  get height() {
    return this.#height;
  }

  /** The settings, whole and frozen. */
  get settings() {
    return this.#settings;
  }

  /** The histogram kernel the pass runs. */
  get histogramKernel() {
    return this.#pipelines[0].kernel.name;
  }

  /** The seed of the frames recorded from now on. */
  get seed() {
    return this.#seed;
  }

  /** Starts an independent render: a new seed for the frames recorded from now on. */
  setSeed(seed) {
    checkU32('seed', seed);
    this.#seed = seed;
  }

  /** The histogram's outputs: `sortedPixels` (per block, pixel indices) and `spans` (ClusterSpan per pixel). */
  get histogramBuffers() {
    return { sortedPixels: this.#own.sorted_pixels, spans: this.#own.spans };
  }

  /** Bytes per pixel of each engine buffer, and bytes each needs for this image. */
  bufferSize(role) {
    if (!ENGINE_ROLES.includes(role)) {
      throw new StrataError('role', `role = ${show(role)}: must be ${inWords(ENGINE_ROLES)}`);
    }
    return ruleBytes(role, this.width * this.height, 0);
  }

  /** The parameters frame `frame` runs with. */
  frameParams(frame, identityPayload = false) {
    return frameParams(this.settings, this.width, this.height, {
      frame,
      seed: this.#seed,
      identityPayload,
      maxWorkgroups: this.#device.limits.maxComputeWorkgroupsPerDimension,
    });
  }

  // One engine buffer, checked: { buffer, offset, size } with the size from its offset.
  #slice(field, role, given) {
    const slice = typeof GPUBuffer !== 'undefined' && given instanceof GPUBuffer ? { buffer: given, offset: 0 } : given;
    if (slice === null || typeof slice !== 'object' || !(slice.buffer instanceof GPUBuffer)) {
      throw new StrataError(field, `${field} = ${show(given)}: must be a GPUBuffer or { buffer: GPUBuffer, offset }`);
    }
    const offset = slice.offset ?? 0;
    if (!Number.isInteger(offset) || offset < 0) {
      throw new StrataError(`${field}.offset`, `${field}.offset = ${show(offset)}: must be a whole number of bytes`);
    }
    if (!(slice.buffer.usage & GPUBufferUsage.STORAGE)) {
      throw new StrataError(field, `buffer \`${role}\` (${field}) lacks the usage GPUBufferUsage.STORAGE (create it with it)`);
    }
    const alignment = this.#device.limits.minStorageBufferOffsetAlignment;
    if (offset % alignment !== 0) {
      throw new StrataError(
        `${field}.offset`,
        `buffer \`${role}\` (${field}) is bound at offset ${offset}, which is not a multiple of ${alignment} (minStorageBufferOffsetAlignment)`,
      );
    }
    const available = slice.buffer.size - offset;
    const needed = this.bufferSize(role);
    if (available < needed) {
      const perPixel = ruleBytes(role, 1, 0);
      throw new StrataError(
        field,
        `buffer \`${role}\` (${field}) has ${Math.max(available, 0)} bytes from its offset, but a ${this.width}x${this.height} image needs ${needed} (${perPixel} bytes per pixel)`,
      );
    }
    // Bound with the bytes the image needs, not the rest of the buffer: two roles may
    // share one buffer at disjoint offsets, and a large buffer may exceed the binding
    // limit where the part the pass uses does not.
    const size = needed;
    const max = this.#device.limits.maxStorageBufferBindingSize;
    if (size > max) {
      throw new StrataError(
        field,
        `buffer \`${role}\` (${field}) is bound with ${size} bytes, more than the device limit maxStorageBufferBindingSize (${max} bytes)`,
      );
    }
    return { buffer: slice.buffer, offset, size, role, field };
  }

  /**
   * Checks the engine's buffers ({ candidates, payloads?, selections, resample?: { inputs,
   * outputs } }, each a GPUBuffer or { buffer, offset }) and makes their bind groups.
   */
  bind(buffers) {
    if (buffers === null || typeof buffers !== 'object') {
      throw new StrataError('buffers', `buffers = ${show(buffers)}: must be { candidates, selections, ... }`);
    }
    const names = ['candidates', 'payloads', 'selections', 'resample'];
    for (const key of Object.keys(buffers)) {
      if (!names.includes(key)) {
        throw new StrataError(`buffers.${key}`, `buffers.${key}: not a buffer of the pass (they are ${inWords(names)})`);
      }
    }
    const slices = {};
    for (const [key, role] of [
      ['candidates', 'candidates'],
      ['selections', 'selections'],
    ]) {
      if (buffers[key] === undefined) {
        throw new StrataError(`buffers.${key}`, `buffers.${key} is missing: the pass needs the engine's \`${role}\` buffer`);
      }
      slices[role] = this.#slice(`buffers.${key}`, role, buffers[key]);
    }
    if (buffers.payloads !== undefined && buffers.payloads !== null) {
      slices.payloads = this.#slice('buffers.payloads', 'payloads', buffers.payloads);
    }
    const resample = buffers.resample !== undefined && buffers.resample !== null;
    if (resample) {
      if (typeof buffers.resample !== 'object') {
        throw new StrataError('buffers.resample', `buffers.resample = ${show(buffers.resample)}: must be { inputs, outputs }`);
      }
      for (const key of Object.keys(buffers.resample)) {
        if (key !== 'inputs' && key !== 'outputs') {
          throw new StrataError(`buffers.resample.${key}`, `buffers.resample.${key}: not a buffer of the pass (they are "inputs" or "outputs")`);
        }
      }
      for (const [key, role] of [
        ['inputs', 'resample_inputs'],
        ['outputs', 'resampled'],
      ]) {
        const field = `buffers.resample.${key}`;
        if (buffers.resample[key] === undefined) {
          throw new StrataError(field, `${field} is missing: resampling needs the engine's \`${role}\` buffer`);
        }
        slices[role] = this.#slice(field, role, buffers.resample[key]);
      }
    }
    const all = Object.values(slices);
    for (let i = 0; i < all.length; i++) {
      for (let j = i + 1; j < all.length; j++) {
        const [a, b] = [all[i], all[j]];
        if (a.buffer === b.buffer && a.offset < b.offset + b.size && b.offset < a.offset + a.size) {
          throw new StrataError(
            b.field,
            `buffers \`${a.role}\` (bytes ${a.offset}..${a.offset + a.size}) and \`${b.role}\` (bytes ${b.offset}..${b.offset + b.size}) overlap in one buffer: each needs bytes of its own`,
          );
        }
      }
    }
    const resource = (name) => {
      if (name === 'payloads' && !slices.payloads) return { buffer: this.#own.unused_payloads };
      const own = this.#own[name];
      if (own) return { buffer: own };
      const slice = slices[name];
      return slice ? { buffer: slice.buffer, offset: slice.offset, size: slice.size } : undefined;
    };
    const group = (pipeline) =>
      this.#device.createBindGroup({
        label: `${this.#label} ${pipeline.kernel.name}`,
        layout: pipeline.layout,
        entries: pipeline.kernel.bindings.map((b) => ({ binding: b.binding, resource: resource(b.buffer) })),
      });
    const [histogram, select, resampling] = this.#pipelines;
    const groups = [group(histogram), group(select), resample ? group(resampling) : null];
    return new StrataBindings(this, groups, !slices.payloads, resample);
  }

  #checkBindings(bindings) {
    if (!(bindings instanceof StrataBindings) || !bindings.belongsTo(this)) {
      throw new StrataError('bindings', `bindings = ${show(bindings)}: must be what this pass's bind() returned`);
    }
  }

  /**
   * Records frame `frame`'s histogram and selection into `encoder` (one compute pass)
   * after writing the frame's uniforms with device.queue.writeBuffer: record at most one
   * frame per queue submission.
   */
  encodeSelection(encoder, bindings, frame) {
    this.#checkBindings(bindings);
    const params = this.frameParams(frame, bindings.identityPayload);
    const queue = this.#device.queue;
    for (const [stage, values] of [
      ['histogram', params.histogram],
      ['select', params.selection],
    ]) {
      const uniform = uniformOf(stage);
      queue.writeBuffer(this.#own[uniform.buffer], 0, pack(uniform.struct, values));
    }
    const pass = encoder.beginComputePass({ label: `${this.#label} histogram + selection` });
    pass.setPipeline(this.#pipelines[0].pipeline);
    pass.setBindGroup(0, bindings.groups[0]);
    pass.dispatchWorkgroups(...params.histogramWorkgroups);
    pass.setPipeline(this.#pipelines[1].pipeline);
    pass.setBindGroup(0, bindings.groups[1]);
    pass.dispatchWorkgroups(...params.pixelWorkgroups);
    pass.end();
  }

  /** Records the resampling of the engine's `resample_inputs` (written after this frame's selection). */
  encodeResampling(encoder, bindings) {
    this.#checkBindings(bindings);
    if (!bindings.resample) {
      throw new StrataError(
        'bindings.resample',
        'the bindings were made without resampling buffers (buffers.resample), so resampling cannot be recorded',
      );
    }
    const [sx, sy] = kernelOfStage('resample').workgroup_size;
    const pass = encoder.beginComputePass({ label: `${this.#label} resampling` });
    pass.setPipeline(this.#pipelines[2].pipeline);
    pass.setBindGroup(0, bindings.groups[2]);
    pass.dispatchWorkgroups(ceilDiv(this.width, sx), ceilDiv(this.height, sy), 1);
    pass.end();
  }

  /** Frees the pass's own buffers (the engine's stay). */
  destroy() {
    Object.values(this.#own).forEach((b) => b.destroy());
  }
}
