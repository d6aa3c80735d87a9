// strata.d.ts: TypeScript declarations of strata.js (strata @STRATA_VERSION@), the
// stratified selection pass (Salaün et al., SIGGRAPH 2025, §4) on a WebGPU device.
// Written by `cargo xtask export`; the unions of names below come from manifest.json.
// Needs the WebGPU types (@webgpu/types, or TypeScript's DOM library with WebGPU).

/** A sampler variant's name (where in a cluster's sorted run the K candidates are taken). */
export type SamplerName = @STRATA_SAMPLER_NAMES@;

/** A block size B: candidates are sorted per B x B block. */
export type BlockSize = @STRATA_BLOCK_SIZES@;

/** A histogram kernel (all give the same output). */
export type HistogramKernel = @STRATA_HISTOGRAM_KERNELS@;

/** A record of the pass's buffers. */
export type RecordName = @STRATA_RECORD_NAMES@;

/** The selection's settings; a field left out takes DEFAULT_SETTINGS'. */
export interface StrataSettings {
  /** B: candidates are sorted per B x B block of pixels (the paper's 16). */
  blockSize?: BlockSize;
  /** K: candidates selected per pixel besides its own, 1 to CONSTANTS.MAX_SELECTED (the paper's 4). */
  candidates?: number;
  /** Where in a cluster's sorted run the candidates are taken (the paper's "antithetic"). */
  sampler?: SamplerName;
  /** Candidates cluster by object id within a block (§4.3). */
  masking?: boolean;
  /** The block grid moves by a new offset every frame. */
  blockShift?: boolean;
}

/** The settings with every field present. */
export type WholeSettings = Readonly<Required<StrataSettings>>;

/** The options of createStrataSelection. */
export interface StrataOptions {
  /** The image's width in pixels. */
  width: number;
  /** The image's height in pixels. */
  height: number;
  /** The selection's settings (DEFAULT_SETTINGS where left out). */
  settings?: StrataSettings;
  /** The render's seed (0 unless given): independent renders need different seeds. */
  seed?: number;
  /** The histogram kernel, or "auto" (the default). */
  histogram?: HistogramKernel | 'auto';
  /** The blue-noise tables (data/blue_noise.bin); fetched next to the module when left out. */
  blueNoise?: ArrayBuffer | ArrayBufferView;
  /** The label of the pass's WebGPU objects. */
  label?: string;
}

/** An engine buffer: a whole GPUBuffer, or one from a byte offset (a multiple of minStorageBufferOffsetAlignment). */
export type StrataBufferSlice = GPUBuffer | { buffer: GPUBuffer; offset?: number };

/** The engine's buffers, each created with GPUBufferUsage.STORAGE. */
export interface StrataBuffers {
  /** One Candidate per pixel (RECORDS.Candidate), written by the engine before the selection. */
  candidates: StrataBufferSlice;
  /** One u32 payload per pixel; left out, a pixel's payload is its index. */
  payloads?: StrataBufferSlice | null;
  /** One SelectedCandidates per pixel, written by the pass. */
  selections: StrataBufferSlice;
  /** The resampling's buffers, if the engine resamples with the pass. */
  resample?: {
    /** One ResampleInput per pixel, written by the engine after the selection. */
    inputs: StrataBufferSlice;
    /** One ResampleOutput per pixel, written by the pass. */
    outputs: StrataBufferSlice;
  } | null;
}

/** What a frame runs with: both uniforms by field, and the dispatches' workgroups. */
export interface StrataFrameParams {
  /** The histogram kernel's uniform (HistogramParams). */
  histogram: Record<string, number>;
  /** strata_select's and strata_resample's uniform (SelectionParams). */
  selection: Record<string, number>;
  /** Workgroups of the histogram dispatch. */
  histogramWorkgroups: [number, number, number];
  /** Workgroups of the per-pixel dispatches. */
  pixelWorkgroups: [number, number, number];
}

/** A record's layout. */
export interface RecordLayout {
  /** Bytes per record. */
  readonly size: number;
  /** Each field's byte offset and WGSL type. */
  readonly fields: Readonly<Record<string, { readonly offset: number; readonly type: string }>>;
}

/** What the module refuses; the message names the field and its value. */
export class StrataError extends Error {
  /** The field that is wrong (`settings.blockSize`, `buffers.candidates`, `device.limits.maxStorageBufferBindingSize`). */
  readonly field: string;
  constructor(field: string, message: string);
}

/** The strata version that wrote the module. */
export const VERSION: string;
/** The constants the kernels and the host share. */
export const CONSTANTS: Readonly<{
@STRATA_CONSTANT_FIELDS@}>;
/** The sampler variants' names. */
export const SAMPLERS: readonly SamplerName[];
/** The block sizes. */
export const BLOCK_SIZES: readonly BlockSize[];
/** The histogram kernels. */
export const HISTOGRAM_KERNELS: readonly HistogramKernel[];
/** The records' layouts. */
export const RECORDS: Readonly<Record<RecordName, RecordLayout>>;
/** The paper's settings. */
export const DEFAULT_SETTINGS: WholeSettings;

/** Checks settings; returns them whole or throws a StrataError naming the field. */
export function checkSettings(settings?: StrataSettings): WholeSettings;
/** The block-grid shift [sx, sy] of frame `frame` of the render `seed`. */
export function gridShift(settings: StrataSettings, frame: number, seed: number): [number, number];
/** Blocks of the largest grid any frame has. */
export function maxBlocks(settings: StrataSettings, width: number, height: number): number;
/** Frame `frame`'s uniforms and workgroup counts. */
export function frameParams(
  settings: StrataSettings,
  width: number,
  height: number,
  frame: { frame: number; seed: number; identityPayload: boolean; maxWorkgroups: number },
): StrataFrameParams;

/** Bind groups of one set of engine buffers (StrataSelection.bind). */
export class StrataBindings {
  private constructor();
  /** Whether the engine bound no payloads buffer (a pixel's payload is its index). */
  readonly identityPayload: boolean;
  /** Whether resampling buffers were bound. */
  readonly resample: boolean;
  /** The bind groups of the histogram, the selection and the resampling (null without resampling buffers). */
  readonly groups: readonly [GPUBindGroup, GPUBindGroup, GPUBindGroup | null];
  /** Whether these bindings were made by `pass`'s bind(). */
  belongsTo(pass: StrataSelection): boolean;
}

/** The pass on one device, image size and settings. */
export class StrataSelection {
  private constructor();
  /** The image's width. */
  readonly width: number;
  /** The image's height. */
  readonly height: number;
  /** The settings, whole and frozen. */
  readonly settings: Readonly<WholeSettings>;
  /** The histogram kernel the pass runs. */
  readonly histogramKernel: HistogramKernel;
  /** The seed of the frames recorded from now on. */
  readonly seed: number;
  /** The histogram's outputs, valid after encodeSelection. */
  readonly histogramBuffers: { sortedPixels: GPUBuffer; spans: GPUBuffer };
  /** Starts an independent render with a new seed. */
  setSeed(seed: number): void;
  /** Bytes an engine buffer needs for this image. */
  bufferSize(role: 'candidates' | 'payloads' | 'selections' | 'resample_inputs' | 'resampled'): number;
  /** The parameters frame `frame` runs with. */
  frameParams(frame: number, identityPayload?: boolean): StrataFrameParams;
  /** Checks the engine's buffers and makes their bind groups. */
  bind(buffers: StrataBuffers): StrataBindings;
  /** Writes frame `frame`'s uniforms and records its histogram and selection. */
  encodeSelection(encoder: GPUCommandEncoder, bindings: StrataBindings, frame: number): void;
  /** Records the resampling (after the engine wrote resample_inputs). */
  encodeResampling(encoder: GPUCommandEncoder, bindings: StrataBindings): void;
  /** Frees the pass's own buffers. */
  destroy(): void;
}

/** Makes the pass on `device`; throws a StrataError naming a bad option, setting or device limit. */
export function createStrataSelection(device: GPUDevice, options: StrataOptions): Promise<StrataSelection>;
