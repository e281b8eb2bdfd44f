// The parts of three.js the HTML report's 3D replay uses (src/report/web/report.js), bundled
// and minified by esbuild into one IIFE that sets `window.THREE`, which the build embeds in the
// tubeplan binary. Only what is named here ends up in the page (esbuild drops the rest).
export {
  AmbientLight,
  ArrowHelper,
  BoxGeometry,
  BufferGeometry,
  CatmullRomCurve3,
  Color,
  CylinderGeometry,
  DirectionalLight,
  DoubleSide,
  EdgesGeometry,
  Float32BufferAttribute,
  GridHelper,
  Group,
  LineBasicMaterial,
  LineSegments,
  Mesh,
  MeshBasicMaterial,
  MeshLambertMaterial,
  PerspectiveCamera,
  RingGeometry,
  Scene,
  SphereGeometry,
  TubeGeometry,
  Vector3,
  WebGLRenderer,
} from 'three';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
