#version 3.7;
camera { location <0, 1, -3> look_at <0, 0, 0> }
#declare Cloth = mesh2 {
  #local spring_system_fixed = true;
  vertex_vectors { 3, <0, 0, 0>, <1, 0, 0>, <0, 0, 1> }
  face_indices { 1, <0, 1, 2> }
object { Cloth }
