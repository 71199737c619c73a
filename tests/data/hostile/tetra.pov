// A tetrahedron over a floor: the smallest scene `film` simulates (hostile-option tests).
#version 3.7;
camera { location <0, 0.7, -2> look_at <0, 0.4, 0> angle 45 }
light_source { <2, 4, -3> color rgb 1.0 }
#declare Floor = mesh2 {
  #local spring_system_fixed = true;
  vertex_vectors { 4, <-1, 0, -1>, <1, 0, -1>, <1, 0, 1>, <-1, 0, 1> }
  face_indices { 2, <0, 2, 1>, <0, 3, 2> }
}
object { Floor }
#declare Tetra = mesh2 {
  #local spring_system_ks = 400;
  #local spring_system_kb = 400;
  #local spring_system_ds = 0.2;
  #local spring_system_db = 0.2;
  #local spring_system_mass = 0.1;
  #local spring_system_vicinity = 0;
  vertex_vectors { 4, <0, 0.5, 0>, <0.1, 0.5, 0>, <0, 0.6, 0>, <0, 0.5, 0.1> }
  face_indices { 4, <0, 2, 1>, <0, 1, 3>, <0, 3, 2>, <1, 2, 3> }
}
object { Tetra }
