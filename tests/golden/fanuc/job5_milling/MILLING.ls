/PROG  MILLING
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 9;
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
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:J P[1] 100% FINE    ;
   4:L P[2] 1000mm/sec FINE    ;
   5:L P[3] 21mm/sec FINE    ;
   6:L P[4] 21mm/sec FINE    ;
   7:L P[5] 21mm/sec FINE    ;
   8:L P[6] 21mm/sec FINE    ;
   9:L P[7] 1000mm/sec FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,
	J1=   107.785 deg,	J2=   -44.953 deg,	J3=   141.647 deg,
	J4=   107.668 deg,	J5=   -87.935 deg,	J6=     6.377 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =     0.000  mm,	Y =  -600.000  mm,	Z =     6.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =   276.225  mm,	Y =  -600.000  mm,	Z =     6.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =   276.225  mm,	Y =  -276.150  mm,	Z =     6.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =  -160.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =     0.000  mm,	Y =  -276.150  mm,	Z =     6.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =     0.000  mm,	Y =  -600.000  mm,	Z =     6.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 1, 0',
	X =     0.000  mm,	Y =  -600.000  mm,	Z =   106.350  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =   180.000 deg
};
/END
