// An array of the drawn surface (positions, normals, colours as bytes or triangles) in a WebGL buffer made
// here and filled a range at a time. three.js's own attributes upload a whole array in one call:
// 25 MB at 692k vertices, most of a second of the page's thread on a software renderer while the
// server computes a basis beside it. Changed ranges wait for `flush`, which uploads at most a
// budget of bytes of them, so that a large mesh is uploaded over several tasks; a whole new
// frame goes to a second buffer meanwhile (`frame`), drawn once it is all there.
import * as THREE from 'three';

export type GpuTypedArray = Float32Array | Uint32Array | Uint8Array;

export class GpuArray {
  attribute: THREE.GLBufferAttribute;
  private buffer: WebGLBuffer | null = null;
  private pending: [number, number][] = []; // [begin, end) elements of `array` not uploaded yet
  private back: WebGLBuffer | null = null; // the next frame's buffer, while it is filled
  private backDone = -1; // elements of `array` in it so far; -1: no frame pending

  // `target`: ARRAY_BUFFER for vertex attributes, ELEMENT_ARRAY_BUFFER for triangles.
  constructor(
    private readonly gl: WebGL2RenderingContext,
    private readonly target: GLenum,
    private readonly itemSize: number,
    public array: GpuTypedArray,
  ) {
    this.attribute = this.allocate(array);
  }

  // Another array, all of it to upload; `same`: it holds the values of the one it replaces (what
  // was pending still is). A new length makes a new buffer and attribute: the geometry takes
  // `drawn` again.
  set(array: GpuTypedArray, same = false): void {
    if (array.length !== this.array.length) this.attribute = this.allocate(array);
    this.array = array;
    this.backDone = -1; // a frame on its way is dropped
    if (!same) this.pending = [[0, array.length]];
  }

  // A new buffer for `array`, whose values are uploaded as they come (update): a new buffer
  // holds zeros.
  fresh(array: GpuTypedArray): void {
    this.attribute = this.allocate(array);
    this.array = array;
    this.pending = [];
  }

  // Items [first, first + count) changed.
  update(first: number, count: number): void {
    if (count > 0) this.pending.push([first * this.itemSize, (first + count) * this.itemSize]);
  }

  // A whole new frame (the same length): uploaded into a second buffer by flushFrame while this
  // one is drawn (a newer frame meanwhile starts it again).
  frame(array: GpuTypedArray): void {
    this.array = array;
    this.pending = [];
    this.backDone = 0;
  }

  // Uploads up to `budget` bytes of a pending frame; returns the bytes uploaded.
  flushFrame(budget: number): number {
    if (this.backDone < 0 || this.frameReady) return 0;
    const gl = this.gl;
    if (!this.back) {
      this.back = gl.createBuffer();
      gl.bindBuffer(this.target, this.back);
      gl.bufferData(this.target, this.array.byteLength, gl.DYNAMIC_DRAW);
    }
    const size = this.array.BYTES_PER_ELEMENT;
    const stop = Math.min(this.array.length, this.backDone + Math.max(1, Math.floor(budget / size)));
    gl.bindBuffer(this.target, this.back);
    gl.bufferSubData(this.target, size * this.backDone, this.array, this.backDone, stop - this.backDone);
    const bytes = size * (stop - this.backDone);
    this.backDone = stop;
    return bytes;
  }

  // A frame is on its way, or all there (frameReady) to be drawn (swap).
  get framePending(): boolean {
    return this.backDone >= 0;
  }

  get frameReady(): boolean {
    return this.backDone === this.array.length;
  }

  // The frame all there is drawn from here: a new `attribute`.
  swap(): void {
    [this.buffer, this.back, this.backDone] = [this.back, this.buffer, -1];
    const a = this.attribute;
    this.attribute = new THREE.GLBufferAttribute(this.buffer!, a.type, a.itemSize, a.elementSize, a.count, a.normalized);
  }

  // The attribute as a geometry takes it: three.js draws a GLBufferAttribute where a
  // BufferAttribute goes, which its type declarations do not say.
  get drawn(): THREE.BufferAttribute {
    return this.attribute as unknown as THREE.BufferAttribute;
  }

  get pendingBytes(): number {
    return this.pending.reduce((sum, [b, e]) => sum + this.array.BYTES_PER_ELEMENT * (e - b), 0);
  }

  // Uploads pending ranges in order, at most `budget` bytes (the rest waits for the next call);
  // returns the bytes uploaded. The caller resets three.js's GL state around it.
  flush(budget: number): number {
    let done = 0;
    const gl = this.gl;
    const size = this.array.BYTES_PER_ELEMENT;
    gl.bindBuffer(this.target, this.buffer);
    while (this.pending.length > 0 && done < budget) {
      const [begin, end] = this.pending[0];
      const stop = Math.min(end, begin + Math.max(1, Math.floor((budget - done) / size)));
      gl.bufferSubData(this.target, size * begin, this.array, begin, stop - begin);
      done += size * (stop - begin);
      if (stop === end) this.pending.shift();
      else this.pending[0][0] = stop;
    }
    return done;
  }

  private allocate(array: GpuTypedArray): THREE.GLBufferAttribute {
    const gl = this.gl;
    if (this.buffer) gl.deleteBuffer(this.buffer);
    if (this.back) gl.deleteBuffer(this.back);
    [this.back, this.backDone] = [null, -1];
    this.buffer = gl.createBuffer();
    gl.bindBuffer(this.target, this.buffer);
    gl.bufferData(this.target, array.byteLength, gl.DYNAMIC_DRAW);
    // Bytes are colours, normalised to [0, 1] as the shader reads them.
    const type = array instanceof Float32Array ? gl.FLOAT : array instanceof Uint8Array ? gl.UNSIGNED_BYTE : gl.UNSIGNED_INT;
    const size = array.BYTES_PER_ELEMENT as 1 | 4;
    return new THREE.GLBufferAttribute(this.buffer!, type, this.itemSize, size, array.length / this.itemSize, size === 1);
  }
}
