// What ropesim/viewer/assets/viewer.js uses of three.js, as one global THREE (esbuild --format=iife): the core
// classes by name (so esbuild leaves out the rest), orbit controls, and fat lines (WebGL draws 1-px lines only).
export {
  ArrowHelper, BoxGeometry, BufferAttribute, BufferGeometry, CanvasTexture, Color, CylinderGeometry, DirectionalLight,
  DoubleSide, EdgesGeometry, Group, HemisphereLight, Line, LineBasicMaterial, LineDashedMaterial, LineSegments,
  MathUtils, Mesh, MeshBasicMaterial, MeshLambertMaterial, MOUSE, OrthographicCamera, PerspectiveCamera,
  PlaneGeometry, Points, PointsMaterial, REVISION, Scene, Shape, ShapeGeometry, Sprite, SpriteMaterial,
  SRGBColorSpace, TOUCH, Vector2, Vector3, WebGLRenderer,
} from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
export { LineMaterial } from "three/examples/jsm/lines/LineMaterial.js";
export { LineSegments2 } from "three/examples/jsm/lines/LineSegments2.js";
export { LineSegmentsGeometry } from "three/examples/jsm/lines/LineSegmentsGeometry.js";
