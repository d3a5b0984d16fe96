MODULE demo
  ! robocal example: joint and Cartesian targets
  PERS tooldata gun := [TRUE,[[0,0,250],[1,0,0,0]],[5,[0,0,100],[1,0,0,0],0,0,0]];
  PERS wobjdata table := [FALSE,TRUE,"",[[800,-300,200],[0.96891242,0,0,0.24740396]],[[0,0,50],[1,0,0,0]]];
  CONST jointtarget j0 := [[0,0,0,0,30,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p0:=[[2492.654,0.000, 2020.000],[0.50000000,-0.00000000,0.86602540,0.00000000],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST jointtarget j2 := [[150,-30,20,-45,60,95],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p2:=[[-1152.385,2257.580, 1852.710],[0.25949694,-0.26259535,0.83016035,0.41777844],[1,-1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

  PROC main()
    MoveAbsJ j0, v100, fine, tool0;
    MoveJ p0, v100, z10, gun;
    MoveAbsJ [[-25,20,-10,100,-50,-200],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]\NoEOffs, v100, fine, tool0;
    MoveL [[2334.922,-1538.286, 1816.608],[0.03976264,0.23911941,-0.75108722,0.61409187],[-1,1,-3,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]], v100, z10, gun\WObj:=wobj0; ! inline

    MoveAbsJ j2, v100, fine, tool0;
    MoveJ p2, v100, z10, gun\WObj:=table;
  ENDPROC
ENDMODULE
