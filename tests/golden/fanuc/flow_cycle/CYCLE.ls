/PROG  CYCLE
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 64;
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
   1:  R[101:nCount]=0 ;
   2:  R[104:rGap]=2.5 ;
   3:  R[105:bDone]=0 ;
   4:  PR[51,3]=R[104:rGap]*4 ;
   5:  UFRAME_NUM=0 ;
   6:  UTOOL_NUM=1 ;
   7:J P[1] 100% FINE    ;
   8:  IF DI[1]=OFF,JMP LBL[2] ;
   9:  UFRAME_NUM=0 ;
  10:  UTOOL_NUM=1 ;
  11:L P[2] 250mm/sec FINE    ;
  12:  DO[1]=ON ;
  13:  JMP LBL[3] ;
  14:  LBL[2] ;
  15:  WAIT 0.50(sec) ;
  16:  LBL[3] ;
  17:  LBL[4] ;
  18:  IF R[101:nCount]>=3 OR R[105:bDone]=1,JMP LBL[5] ;
  19:  R[101:nCount]=R[101:nCount]+1 ;
  20:  UFRAME_NUM=0 ;
  21:  UTOOL_NUM=1 ;
  22:L P[3] 250mm/sec FINE    ;
  23:  IF R[101:nCount]<2,JMP LBL[6] ;
  24:  R[105:bDone]=1 ;
  25:  LBL[6] ;
  26:  JMP LBL[4] ;
  27:  LBL[5] ;
  28:  FOR R[103:i]=1 TO 3 ;
  29:  UFRAME_NUM=0 ;
  30:  UTOOL_NUM=1 ;
  31:L P[4] 250mm/sec FINE    ;
  32:L P[5] 250mm/sec FINE    ;
  33:  ENDFOR ;
  34:  LBL[7] ;
  35:  WAIT 0.10(sec) ;
  36:  IF DI[2]=OFF AND R[101:nCount]<=5,JMP LBL[7] ;
  37:  R[102:nMode]=2 ;
  38:  SELECT R[102:nMode]=1,JMP LBL[8] ;
  39:       =2,JMP LBL[9] ;
  40:       =3,JMP LBL[9] ;
  41:       ELSE,JMP LBL[10] ;
  42:  LBL[8] ;
  43:  DO[2]=ON ;
  44:  JMP LBL[11] ;
  45:  LBL[9] ;
  46:  UFRAME_NUM=0 ;
  47:  UTOOL_NUM=1 ;
  48:L P[6] 250mm/sec FINE    ;
  49:  JMP LBL[11] ;
  50:  LBL[10] ;
  51:  DO[3]=ON ;
  52:  LBL[11] ;
  53:  LBL[12] ;
  54:  WAIT DI[3]=ON ;
  55:  IF DI[4]=ON,JMP LBL[13] ;
  56:  JMP LBL[14] ;
  57:  LBL[13] ;
  58:  JMP LBL[12] ;
  59:  LBL[14] ;
  60:  JMP LBL[1] ;
  61:  LBL[1:Finish] ;
  62:  UFRAME_NUM=0 ;
  63:  UTOOL_NUM=1 ;
  64:J P[7] 100% FINE    ;
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
	X =   450.000  mm,	Y =   -70.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   375.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
/END
