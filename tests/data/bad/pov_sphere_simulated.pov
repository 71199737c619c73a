#version 3.7;
sphere { <0, 1, 0>, 0.5
  #local spring_system_fixed = false;
  pigment { color rgb 1 }
}
