/PROG  WELD_ROUNDED
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 28;
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
   1:  !A fillet weld around a ;
   2:  !rectangular plate, 200 x 120 mm ;
   3:  !with corners rounded to 20 mm: ;
   4:  !four ;
   5:  !straight seams joined by quarter ;
   6:  !circles (CIRC aux, end), blended ;
   7:  !at every junction, with a ;
   8:  !150 mm torch tilted 20 degrees ;
   9:  !sideways (off the wrist ;
  10:  !singularity of a vertical ;
  11:  !torch). ;
  12:  UFRAME_NUM=0 ;
  13:  UTOOL_NUM=1 ;
  14:J P[1] 100% FINE    ;
  15:L P[2] 200mm/sec FINE    ;
  16:L P[3] 200mm/sec FINE    ;
  17:  DO[2]=ON ;
  18:L P[4] 12mm/sec CNT2    ;
  19:C P[5]
    :  P[6] 12mm/sec CNT2    ;
  20:L P[7] 12mm/sec CNT2    ;
  21:C P[8]
    :  P[9] 12mm/sec CNT2    ;
  22:L P[10] 12mm/sec CNT2    ;
  23:C P[11]
    :  P[12] 12mm/sec CNT2    ;
  24:L P[13] 12mm/sec CNT2    ;
  25:C P[14]
    :  P[15] 12mm/sec FINE    ;
  26:  DO[2]=OFF ;
  27:L P[16] 200mm/sec FINE    ;
  28:J P[17] 100% FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   -60.000  mm,	Z =   250.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   -60.000  mm,	Z =   250.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   -60.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   580.000  mm,	Y =   -60.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   594.142  mm,	Y =   -54.142  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   600.000  mm,	Y =   -40.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   600.000  mm,	Y =    40.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   594.142  mm,	Y =    54.142  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   580.000  mm,	Y =    60.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[10]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =    60.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[11]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   405.858  mm,	Y =    54.142  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[12]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   400.000  mm,	Y =    40.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[13]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   400.000  mm,	Y =   -40.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[14]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   405.858  mm,	Y =   -54.142  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[15]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   -60.000  mm,	Z =   200.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[16]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   420.000  mm,	Y =   -60.000  mm,	Z =   250.000  mm,
	W =   180.000 deg,	P =    20.000 deg,	R =    90.000 deg
};
P[17]{
   GP1:
	UF : 0, UT : 1,
	J1=     0.000 deg,	J2=   -80.000 deg,	J3=   100.000 deg,
	J4=     0.000 deg,	J5=    70.000 deg,	J6=     0.000 deg
};
/END
