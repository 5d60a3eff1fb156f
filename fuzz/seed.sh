#!/bin/sh
# fuzz/seed.sh: lays the fuzzers' seed corpus and working folder
# in build-fuzz/ (or $1); generated, never committed. The fuzzers write
# what they find into corpus/scene/ and corpus/mesh/ (made here if missing,
# kept between runs); the seeds are laid anew each time.
#   seeds/scene/    every scenes/**/*.yaml, plus three scenes written here
#                   that use the keys scenes/ does not (mesh cloths,
#                   inline meshes, pins, keyframes, level-set options,
#                   a "#set" override line)
#   seeds/mesh/     the repository's small meshes (assets/ up to 128 KB,
#                   tests/data/bad_meshes/), each behind the byte that
#                   tells mesh_fuzz its extension (and cs_mesh_import)
#   scene.dict      the scene schema's keys and enum values, from
#                   import/scene_schema.c (libFuzzer -dict=)
#   fuzz-root/      what the inputs see: scenes/ (scene_fuzz loads each
#                   input as scenes/fuzz.yaml), assets/ (copies of the
#                   small assets, with stanford-bunny.obj standing in as
#                   ico4.obj at the bunny's size, 642 vertices against
#                   the bunny's 35,947, so that each of bunny_drape's
#                   mutants imports a small mesh), cache/ (level-set cache)
#   artifacts/      where fuzz/README.md's commands put what they find
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build-fuzz"}
small=131072
seeds="$build/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/scene" "$seeds/mesh" "$build/corpus/scene" "$build/corpus/mesh" \
         "$build/artifacts/scene" "$build/artifacts/mesh" \
         "$build/fuzz-root/scenes" "$build/fuzz-root/assets" "$build/fuzz-root/cache"

# ---- working folder: copies of the small assets (and what they refer to)
for f in "$root"/assets/*; do
    [ -f "$f" ] || continue
    size=$(wc -c < "$f")
    case "$f" in
    *.bin|*.mtl) cp "$f" "$build/fuzz-root/assets/" ;;
    *.md|*SUMS) ;;
    *) if [ "$size" -le "$small" ]; then cp "$f" "$build/fuzz-root/assets/"; fi ;;
    esac
done
# the bunny's stand-in: ico4 (2 m across) shrunk and moved onto the bunny's
# box (0.155 m across), so bunny_drape's level set has the bunny's size
awk '/^v /{printf "v %.6f %.6f %.6f\n", ($2-0.24)*0.08-0.017, ($3-0.18)*0.08+0.11, ($4-0.9)*0.08-0.0015; next}
     {print}' "$root/assets/ico4.obj" > "$build/fuzz-root/assets/stanford-bunny.obj"

# ---- scene seeds
find "$root/scenes" -name '*.yaml' | sort | while read -r f; do
    rel=${f#"$root/scenes/"}
    cp "$f" "$seeds/scene/$(echo "$rel" | tr / _)"
done
cat > "$seeds/scene/seed_mesh_cloth.yaml" <<'YAML'
name: seed_mesh_cloth
time: {fps: 30, frames: 2, dt: auto, dt_safety: 0.5, collision_steps: 2, cg_tolerance: 1.0e-6, cg_max_iterations: 40}
gravity: [0, -9.8, 0]
effects: {bodies: true, wind: true, self_collision: true, friction: projection}
self_collision: {thickness: 0.001, stiffness: 10, friction: 0.1, edge_flip_epsilon: 1.0e-6, zone_iterations: 20, scheme: rewind, verify: true}
wind: {velocity: [1, 0, 0], drag: 0.5}
output: {format: glb}
camera: {position: [0, 1, 3], target: [0, 0, 0], up: [0, 1, 0], fov: 35}
levelset: {cache: ../cache}
cloths:
  - name: shell
    color: [0.5, 0.2, 0.2]
    mesh:
      file: ../assets/ico4.obj
      units: cm
      scale: [1, 2, 1]
      rotation: [0, 45, 0]
      translate: [0, 1, 0]
    material: {edge_stiffness: 100, edge_overdamping: 0.5, bend_stiffness: 0.001, bend_overdamping: 0.1, density: 0.2}
    velocity: [0, 0, 0.1]
    pins:
      - vertices: [0, 1, 2]
bodies:
  - name: table
    shape: mesh
    mesh: {file: ../assets/wooden_table_02_1k.gltf, units: auto, scale: 0.5}
    voxel_size: 0.02
    band: 2
    close_holes: true
    interior: band
    friction: 0.3
    collision_offset: 0.001
  - {name: floor, shape: plane, normal: [0, 1, 0], position: [0, -1, 0]}
YAML
cat > "$seeds/scene/seed_inline.yaml" <<'YAML'
name: seed_inline
#set cloths.0.material.node_mass=2e-6
#set time.frames=3
time: {fps: 24, frames: 4, dt: 0.001}
cloths:
  - name: quad
    mesh:
      vertices: [[0, 1, 0], [1, 1, 0], [1, 1, 1], [0, 1, 1]]
      triangles: [[0, 1, 2], [0, 2, 3]]
    material: {node_mass: 1.0e-3}
    scripts:
      - select: {vertices: [0, 1]}
        pivot: [0.5, 1, 0]
        motion:
          keys:
            - {time: 0, translate: [0, 0, 0], rotate: [0, 0, 0]}
            - {time: 1, translate: [0, 0.5, 0], rotate: [0, 90, 0]}
      - select: {box: {min: [-1, 0, 0.5], max: [2, 2, 2]}}
        motion: {velocity: [0, 0.1, 0], angular_velocity: [0, 1, 0]}
bodies:
  - {name: ball, shape: sphere, position: [0.5, 0.5, 0.5], radius: 0.2, motion: {velocity: [0, 0, 0.1]}}
  - {name: crate, shape: box, size: [0.2, 0.2, 0.2], rotation: [10, 20, 30]}
  - {name: post, shape: cylinder, radius: 0.05, height: 0.5, motion: {keys: [{time: 0, translate: [0, 0, 0]}, {time: 2, rotate: [0, 180, 0]}]}}
YAML
cat > "$seeds/scene/seed_grid_pins.yaml" <<'YAML'
name: seed_grid_pins
cloths:
  - name: flag
    grid: {size: [1, 0.5], resolution: [8, 4], center: [0, 1, 0], rotation: [90, 0, 0]}
    pins:
      - grid_points: [[0, 0], [0, 4]]
      - box: {min: [-1, -1, -1], max: [-0.49, 2, 1]}
bodies:
  - name: duck
    shape: mesh
    mesh: {file: ../assets/Spider_binary.stl, node: "", units: mm}
    voxel_size: 0.05
    interior: fill
YAML

# ---- scene dictionary: the key table's names and the schema's quoted
# words (enum values), as "word" and "word:"
{
    grep -o '^CS_KEY([a-z_]*, [a-z_0-9]*' "$root/import/scene_keys.def" | sed 's/.*, //'
    grep -o '"[a-z_][a-z0-9_]*"' "$root/import/scene_schema.c" | tr -d '"'
} | sort -u | while read -r w; do
    printf '"%s"\n' "$w"
    printf '"%s:"\n' "$w"
done > "$build/scene.dict"

# ---- mesh seeds: one byte (extension index, reader 0 = cs_mesh_import),
# then the file; the order is mesh_fuzz.c's extensions[]
ext_byte() {
    case $(echo "$1" | tr 'A-Z' 'a-z') in
    *.ply) echo 000 ;; *.obj) echo 001 ;; *.stl) echo 002 ;; *.glb) echo 003 ;;
    *.gltf) echo 004 ;; *.fbx) echo 005 ;; *.dae) echo 006 ;; *.off) echo 007 ;;
    *) echo "" ;;
    esac
}
for f in "$root"/assets/* "$root"/tests/data/bad_meshes/*; do
    [ -f "$f" ] || continue
    b=$(ext_byte "$f")
    size=$(wc -c < "$f")
    [ -n "$b" ] && [ "$size" -le "$small" ] || continue
    out="$seeds/mesh/$(basename "$(dirname "$f")")_$(basename "$f")"
    { printf "\\$b"; cat "$f"; } > "$out"
done
echo "seeds: $(ls "$seeds/scene" | wc -l) scenes, $(ls "$seeds/mesh" | wc -l) meshes in $seeds"
