// What ropesim/viewer/assets/viewer.js uses of three.js, as one global THREE (esbuild --format=iife): the core
// classes by name (so esbuild leaves out the rest) and the orbit controls.
export {
  ArrowHelper, BoxGeometry, BufferAttribute, BufferGeometry, CanvasTexture, Color, CylinderGeometry, DirectionalLight,
  DoubleSide, DynamicDrawUsage, EdgesGeometry, Group, HemisphereLight, Line, LineBasicMaterial, LineDashedMaterial, LineSegments,
  MathUtils, Mesh, MeshBasicMaterial, MeshLambertMaterial, MOUSE, OrthographicCamera, PerspectiveCamera,
  PlaneGeometry, Points, PointsMaterial, REVISION, Scene, Shape, ShapeGeometry, Sprite, SpriteMaterial,
  ShaderMaterial, SRGBColorSpace, TOUCH, Vector2, Vector3, WebGLRenderer,
} from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
