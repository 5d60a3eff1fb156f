// usd_check.mjs MODULES USDA SPEC.json: checks a cloth.usda written by
// clothsim with TinyUSDZ (a reader we did not write, WebAssembly, from
// npm; MODULES is the node_modules folder holding it) and with a small
// parse of its own, against the frame files (tests/cli_usd.sh).
//
// SPEC: {root, up, fps, start, end, times: [t1, t2], meshes: [{name,
// points, faces, samples, frames: PLY or OBJ of time code t, with %04d}],
// bodies: [{name, samples}]}; bodies are meshes too, whose points are not
// sampled (samples: transform samples, 0 for a static body).
//
// TinyUSDZ's npm build targets browsers: it runs under node once it
// believes it is in one, with its .wasm handed over as bytes.
import fs from 'node:fs';
import path from 'node:path';

const [modules, usda, specFile] = process.argv.slice(2);
const spec = JSON.parse(fs.readFileSync(specFile, 'utf8'));
let failures = 0;
function check(ok, what) {
    if (!ok) {
        console.error(`usd_check: FAIL: ${what}`);
        failures++;
    }
    return ok;
}

// ---------------------------------------------------------- the frames
function readPly(file) {
    const buf = fs.readFileSync(file);
    const end = buf.indexOf('end_header\n');
    const header = buf.subarray(0, end).toString('latin1').split('\n');
    if (!header.includes('format binary_little_endian 1.0'))
        throw new Error(`${file}: not binary little-endian PLY`);
    const sizes = {float: 4, float32: 4, double: 8, uchar: 1, uint8: 1, char: 1, int: 4,
                   int32: 4, uint: 4, uint32: 4, short: 2, ushort: 2};
    let nv = -1, stride = 0, offsets = {}, first = null, current = null;
    for (const line of header) {
        const w = line.split(' ');
        if (w[0] === 'element') {
            current = w[1];
            first = first ?? w[1];
            if (w[1] === 'vertex') nv = +w[2];
        } else if (w[0] === 'property' && current === 'vertex' && first === 'vertex') {
            offsets[w[2]] = stride;
            stride += sizes[w[1]];
        }
    }
    if (first !== 'vertex' || !('x' in offsets)) throw new Error(`${file}: no leading vertices`);
    const base = end + 'end_header\n'.length, x = new Float32Array(3 * nv);
    for (let v = 0; v < nv; v++)
        for (let k = 0; k < 3; k++)
            x[3 * v + k] = buf.readFloatLE(base + v * stride + offsets['xyz'[k]]);
    // the faces, as assimp writes them: a list of uchar count, int indices
    const tri = [];
    if (header.includes('property list uchar int vertex_index'))
        for (let o = base + nv * stride; o < buf.length;) {
            const n = buf.readUInt8(o);
            for (let k = 0; k < n; k++) tri.push(buf.readInt32LE(o + 1 + 4 * k));
            o += 1 + 4 * n;
        }
    return {x, tri};
}

// OBJ frames: `v x y z` and `f a/b/c ...` lines (1-based)
function readObj(file) {
    const xs = [], tri = [];
    for (const line of fs.readFileSync(file, 'utf8').split('\n')) {
        const w = line.trim().split(/\s+/);
        if (w[0] === 'v') xs.push(+w[1], +w[2], +w[3]);
        if (w[0] === 'f') for (const c of w.slice(1)) tri.push(parseInt(c, 10) - 1);
    }
    return {x: Float32Array.from(xs), tri};
}
const readFrame = file => file.endsWith('.obj') ? readObj(file) : readPly(file);

// PLY frames hold float32 bits: equal. OBJ frames hold decimals, which
// assimp's reader (clothsim's) and JavaScript's may round to neighbouring
// float32 values (seen at 1e-16): within one float32 step.
function sameFloat(a, b, text) {
    a = Math.fround(a);
    if (a === b || !text) return a === b;
    return Math.abs(a - b) <= Math.max(Math.abs(a), Math.abs(b)) * 2 ** -23;
}
const framePath = (pattern, t) => pattern.replace('%04d', String(t).padStart(4, '0'));

// ------------------------------------------------- a small parse of USDA
// Enough of the text format for what clothsim writes and TinyUSDZ prints
// back: the stage metadata, the Mesh prims under the root, their points'
// time samples (one sample a line) and transform samples.
function parseUsda(text) {
    const lines = text.split('\n');
    const meta = {}, meshes = {};
    let i = 0;
    if (!lines[0].startsWith('#usda 1.0')) throw new Error('no #usda 1.0 line');
    for (i = 1; i < lines.length && lines[i].trim() !== ')'; i++) {
        const m = lines[i].match(/^\s*(\w+)\s*=\s*(.*)$/);
        if (m) meta[m[1]] = m[2].replace(/^"(.*)"$/, '$1');
    }
    let mesh = null, block = null;
    for (; i < lines.length; i++) {
        const line = lines[i];
        let m;
        if ((m = line.match(/^\s*def Xform "(\w+)"/)) && !mesh) meta.rootPrim = m[1];
        if ((m = line.match(/^\s*def Mesh "(\w+)"/))) {
            mesh = meshes[m[1]] = {samples: new Map(), xformSamples: 0, name: null, tri: []};
            continue;
        }
        if (!mesh) continue;
        if ((m = line.match(/int\[\] faceVertexIndices = \[(.*)\]/)))
            mesh.tri = m[1].split(',').map(Number);
        // a string in double or single quotes (TinyUSDZ prints 'say "hi"')
        if ((m = line.match(/custom string clothsim:name = (?:"((?:[^"\\]|\\.)*)"|'((?:[^'\\]|\\.)*)')/)))
            mesh.name = (m[1] ?? m[2]).replace(/\\(.)/g, '$1');
        if (/points\.timeSamples = \{/.test(line)) { block = 'points'; continue; }
        if (/xformOp:transform\.timeSamples = \{/.test(line)) { block = 'xform'; continue; }
        if (block && /^\s*\}\s*$/.test(line)) { block = null; continue; }
        if (block === 'points' && (m = line.match(/^\s*([-\d.e+]+)\s*:\s*\[(.*)\],?\s*$/))) {
            const triples = [...m[2].matchAll(/\(([^()]*)\)/g)];
            const x = new Float32Array(3 * triples.length);
            triples.forEach((t, v) => t[1].split(',').forEach((s, k) => { x[3 * v + k] = +s; }));
            mesh.samples.set(+m[1], x);
        } else if (block === 'xform' && /^\s*[-\d.e+]+\s*:/.test(line)) {
            mesh.xformSamples++;
        }
    }
    return {meta, meshes};
}

// the stage as parsed (ours, or TinyUSDZ's print of it) against spec
function checkStage(stage, who) {
    const {meta, meshes} = stage;
    check(meta.rootPrim === spec.root && meta.defaultPrim === spec.root,
          `${who}: root prim ${meta.rootPrim}, defaultPrim ${meta.defaultPrim}, not ${spec.root}`);
    check(meta.upAxis === spec.up, `${who}: upAxis ${meta.upAxis}, not ${spec.up}`);
    check(+meta.metersPerUnit === 1, `${who}: metersPerUnit ${meta.metersPerUnit}`);
    for (const k of ['timeCodesPerSecond', 'framesPerSecond'])
        check(+meta[k] === spec.fps, `${who}: ${k} ${meta[k]}, not ${spec.fps}`);
    check(+meta.startTimeCode === spec.start && +meta.endTimeCode === spec.end,
          `${who}: time codes ${meta.startTimeCode} to ${meta.endTimeCode}, not ` +
          `${spec.start} to ${spec.end}`);
    const want = spec.meshes.length + spec.bodies.length;
    check(Object.keys(meshes).length === want,
          `${who}: ${Object.keys(meshes).length} Mesh prims, not ${want}`);
    for (const s of spec.meshes) {
        const m = meshes[s.name];
        if (!check(m, `${who}: no Mesh prim ${s.name}`)) continue;
        check(m.samples.size === s.samples,
              `${who}: ${s.name} has ${m.samples.size} point samples, not ${s.samples}`);
        if (s.given) check(m.name === s.given, `${who}: ${s.name}'s clothsim:name ${m.name}`);
        const codes = [...m.samples.keys()];
        check(codes[0] === spec.start && codes[codes.length - 1] === spec.end,
              `${who}: ${s.name}'s samples run ${codes[0]} to ${codes[codes.length - 1]}`);
        for (const t of spec.times) {
            const file = framePath(s.frames, t), text = file.endsWith('.obj');
            const x = m.samples.get(t), frame = readFrame(file), ref = frame.x;
            if (!check(x, `${who}: ${s.name} has no sample at ${t}`)) continue;
            check(x.length === 3 * s.points, `${who}: ${s.name} at ${t}: ${x.length / 3} points`);
            let bad = -1;
            for (let i = 0; i < ref.length && bad < 0; i++)
                if (!sameFloat(x[i], ref[i], text)) bad = i;
            check(x.length === ref.length && bad < 0,
                  `${who}: ${s.name} at ${t}: coordinate ${bad} is ${x[bad]}, the frame file's ` +
                  `${ref[bad]}`);
            // the topology: every triangle's corners where the frame has them
            let badTri = -1;
            for (let i = 0; i < frame.tri.length && badTri < 0; i++)
                for (let k = 0; k < 3; k++)
                    if (!sameFloat(x[3 * m.tri[i] + k], ref[3 * frame.tri[i] + k], text)) badTri = i;
            check(frame.tri.length === 3 * s.faces && m.tri.length === frame.tri.length &&
                  badTri < 0, `${who}: ${s.name} at ${t}: corner ${badTri} of the triangles ` +
                  `is not the frame file's`);
        }
        console.log(`${who}: ${s.name}: ${m.samples.size} samples, codes ${codes[0]} to ` +
                    `${codes[codes.length - 1]}; ${s.points} points and ${s.faces} triangles ` +
                    (s.frames.endsWith('.obj') ? 'within a float32 step of the OBJ frames '
                                               : 'equal to the float32 of frames ') +
                    spec.times.join(' and '));
    }
    for (const b of spec.bodies) {
        const m = meshes[b.name];
        if (!check(m, `${who}: no body Mesh prim ${b.name}`)) continue;
        check(m.samples.size === 0, `${who}: body ${b.name} has point samples`);
        check(m.xformSamples === b.samples,
              `${who}: body ${b.name} has ${m.xformSamples} transform samples, not ${b.samples}`);
    }
}

// -------------------------------------------------------------- TinyUSDZ
globalThis.window = globalThis;   // the web build asks for a window
process.type = 'renderer';        // and is refused under plain node
const dir = path.join(modules, 'tinyusdz');
const { default: init } = await import(path.join(dir, 'tinyusdz.js'));
const tiny = await init({ wasmBinary: fs.readFileSync(path.join(dir, 'tinyusdz.wasm')) });
const bytes = new Uint8Array(fs.readFileSync(usda));

// 1. the stage as a renderer sees it: meshes, their point and face counts
const scene = new tiny.TinyUSDZLoaderNative();
check(scene.loadFromBinary(bytes, usda), `TinyUSDZ cannot load ${usda}: ${scene.error()}`);
const want = spec.meshes.length + spec.bodies.length;
check(scene.numMeshes() === want, `TinyUSDZ: ${scene.numMeshes()} meshes, not ${want}`);
const seen = {};
for (let i = 0; i < scene.numMeshes(); i++) {
    const m = scene.getMesh(i);
    seen[m.absPath] = m;
}
for (const s of [...spec.meshes, ...spec.bodies]) {
    const m = seen[`/${spec.root}/${s.name}`];
    if (!check(m, `TinyUSDZ: no mesh /${spec.root}/${s.name}`)) continue;
    const counts = Array.from(m.faceVertexCounts);
    check(!s.points || m.points.length === 3 * s.points,
          `TinyUSDZ: ${s.name} has ${m.points.length / 3} points, not ${s.points}`);
    check(!s.faces || counts.length === s.faces,
          `TinyUSDZ: ${s.name} has ${counts.length} faces, not ${s.faces}`);
    check(counts.every(n => n === 3) && m.faceVertexIndices.length === 3 * counts.length,
          `TinyUSDZ: ${s.name}'s faces are not all triangles`);
    console.log(`TinyUSDZ render scene: /${spec.root}/${s.name}: ${m.points.length / 3} ` +
                `points, ${counts.length} triangles`);
}

// 2. the layer as TinyUSDZ parsed it (time samples included), printed back
const layer = new tiny.TinyUSDZLoaderNative();
check(layer.loadAsLayerFromBinary(bytes, usda), `TinyUSDZ cannot load the layer: ${layer.error()}`);
checkStage(parseUsda(layer.layerToString()), 'TinyUSDZ layer');

// 3. the file itself, parsed here
checkStage(parseUsda(fs.readFileSync(usda, 'utf8')), 'own parse');

if (failures) process.exit(1);
console.log('usd_check: ok');
