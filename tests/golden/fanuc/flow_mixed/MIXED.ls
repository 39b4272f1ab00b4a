/PROG  MIXED
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 25;
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
   1:  R[101:nParts]=0 ;
   2:  R[102:nRow]=1 ;
   3:  R[103:rPitch]=42.5 ;
   4:  UFRAME_NUM=0 ;
   5:  UTOOL_NUM=1 ;
   6:J P[1] 100% FINE    ;
   7:  LBL[1] ;
   8:  IF ((DI[1]=OFF AND DI[2]=OFF) OR R[101:nParts]>=6),JMP LBL[2] ;
   9:  R[104:rOffset]=(((R[102:nRow]-1)*R[103:rPitch])+10) ;
  10:  WAIT (DI[3]=ON AND (DI[4]=ON OR DI[5]=OFF)) ;
  11:  UFRAME_NUM=0 ;
  12:  UTOOL_NUM=1 ;
  13:L P[2] 100mm/sec FINE    ;
  14:  DO[1]=ON ;
  15:L P[3] 100mm/sec FINE    ;
  16:  R[101:nParts]=R[101:nParts]+1 ;
  17:  IF ((R[101:nParts]-(R[102:nRow]*3))<0),JMP LBL[3] ;
  18:  R[102:nRow]=R[102:nRow]+1 ;
  19:  LBL[3] ;
  20:  JMP LBL[1] ;
  21:  LBL[2] ;
  22:  R[104:rOffset]=(-1.5) ;
  23:  UFRAME_NUM=0 ;
  24:  UTOOL_NUM=1 ;
  25:J P[4] 100% FINE    ;
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
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   275.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   375.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
/END
