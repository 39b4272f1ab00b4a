/PROG  TRANSPILE
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 21;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !A KRL program that runs on both ;
   2:  !the UR5e screwdriving cell and ;
   3:  !the Fanuc M-20iA welding cell ;
   4:  !(tool 1 of each station, a base ;
   5:  !frame in front of both robots): ;
   6:  !the transpiling goldens. ;
   7:  UFRAME_NUM=0 ;
   8:  UTOOL_NUM=1 ;
   9:J P[1] 100% FINE    ;
  10:L P[2] 250mm/sec FINE    ;
  11:  DO[1]=ON ;
  12:  WAIT 0.50(sec) ;
  13:L P[3] 50mm/sec CNT20    ;
  14:L P[4] 50mm/sec CNT20    ;
  15:L P[5] 50mm/sec CNT20    ;
  16:L P[6] 50mm/sec CNT20    ;
  17:L P[7] 50mm/sec FINE    ;
  18:  DO[1]=OFF ;
  19:  WAIT DI[2]=ON ;
  20:L P[8] 250mm/sec CNT20    ;
  21:J P[9] 100% FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   275.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   550.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   550.000  mm,	Y =   -70.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   550.000  mm,	Y =     0.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =     0.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =    90.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   275.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   375.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
/END
