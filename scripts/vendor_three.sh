#!/bin/bash
# Builds crates/kerf-view/vendor/three.bundle.min.js: three.js (npm `three`, MIT) with
# OrbitControls, only the classes the viewer uses, minified by esbuild into one classic script
# that sets the global THREE (a view.html opens from the disk, where ES modules cannot import
# each other). Run it when crates/kerf-view/src/view.js needs another class of three.js.
#   scripts/vendor_three.sh [VERSION]
set -eu
VERSION=${1:-0.187.0}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
npm init -y >/dev/null
npm install --silent --no-audit --no-fund "three@$VERSION" esbuild@0.25 >/dev/null
cat > entry.js <<'JS'
export {
  AmbientLight, Box3, BufferGeometry, Color, CylinderGeometry, DirectionalLight, DoubleSide,
  Float32BufferAttribute, Group, Line, LineBasicMaterial, LineDashedMaterial, LineSegments, Mesh,
  MeshBasicMaterial, MeshStandardMaterial, OctahedronGeometry, PerspectiveCamera, Raycaster,
  Scene, SphereGeometry, Vector2, Vector3, WebGLRenderer,
} from 'three';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
JS
npx esbuild entry.js --bundle --minify --format=iife --global-name=THREE \
  --legal-comments=none --outfile=bundle.js
{
  echo "/* three.js r$(echo "$VERSION" | cut -d. -f2) (https://threejs.org), MIT licence: vendor/three.LICENSE.txt. Built by scripts/vendor_three.sh. */"
  cat bundle.js
} > "$ROOT/crates/kerf-view/vendor/three.bundle.min.js"
cp node_modules/three/LICENSE "$ROOT/crates/kerf-view/vendor/three.LICENSE.txt"
ls -l "$ROOT/crates/kerf-view/vendor/three.bundle.min.js"
